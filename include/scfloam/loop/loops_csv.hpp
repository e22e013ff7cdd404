// loops.csv: every loop candidate with its verdict, one row each, a header line first.
// Columns: current_frame, loop_frame, current_kf, loop_kf, sc_score, yaw_rad, distance_m,
// gate_m, verdict, ring_key_distance, match_inlier_fraction, match_residual_m
// (the last two empty until loop registration fills them).
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <vector>

#include "scfloam/loop/loop_candidate.hpp"
#include "scfloam/loop/loop_detector.hpp"

namespace scfloam {

// Written through write_file_atomic; throws scfloam::Error naming the file on failure.
void write_loops_csv(const std::filesystem::path& path, const std::vector<LoopCandidate>& rows);
// Reads columns by header name (any order, extra columns ignored); the first nine are required.
std::vector<LoopCandidate> read_loops_csv(const std::filesystem::path& path);

// The rows of a run, collected query by query; the verdict of the accepted row can be changed
// after loop registration.
class LoopLog {
 public:
  // Appends rows_to_log(query); returns the row of query.best, if there is one.
  std::optional<std::size_t> add(const LoopQuery& query);
  void add(const LoopCandidate& row) { rows_.push_back(row); }
  // Records the registration outcome of a row (kAccepted or kRejectedMatch and the match quality).
  void set_match(std::size_t row, LoopVerdict verdict, double inlier_fraction, double residual_m);

  const std::vector<LoopCandidate>& rows() const { return rows_; }
  void write(const std::filesystem::path& path) const { write_loops_csv(path, rows_); }

 private:
  std::vector<LoopCandidate> rows_;
};

}  // namespace scfloam
