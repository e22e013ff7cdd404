// The evaluation figure, one SVG with four panels: top view of estimate vs ground truth (with
// accepted loop closures as links), t_err and r_err vs segment length, and the per-frame
// translation error (ATE) along the path.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "scfloam/eval/report.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

struct LoopLink {
  std::size_t current_frame = 0, loop_frame = 0;
};

// The rows of a loops.csv (header with columns current_frame, loop_frame, ..., verdict) whose
// verdict is "accepted". Throws scfloam::Error naming the file on a missing column or bad row.
std::vector<LoopLink> read_accepted_loops(const std::filesystem::path& path);

// Loop frames are rows of the estimate file; re-index them to positions in the associated
// lists (est_index[k] = file row of pair k). Loops touching unpaired frames are dropped.
std::vector<LoopLink> loops_to_pairs(const std::vector<LoopLink>& loops,
                                     const std::vector<std::size_t>& est_index);

struct EvalPlotInput {
  const EvalReport* report = nullptr;
  const PoseList* gt = nullptr;   // associated ground truth
  const PoseList* est = nullptr;  // associated estimate, raw (as in the file)
  std::vector<LoopLink> loops;    // indices into gt/est
  bool draw_aligned = false;      // top view: estimate after SE(3) alignment instead of raw
  std::string heading;            // first line of the figure, e.g. the file names
};

std::string eval_plot_svg(const EvalPlotInput& input);
void write_eval_plot_svg(const std::filesystem::path& path, const EvalPlotInput& input);

}  // namespace scfloam
