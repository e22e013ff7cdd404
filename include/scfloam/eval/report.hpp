// Every accuracy figure of one estimate against its ground truth, as a table for people and
// one JSON line for programs. `scfloam run` and `scfloam eval` both print these.
#pragma once

#include <string>

#include "scfloam/eval/alignment.hpp"
#include "scfloam/eval/kitti_metric.hpp"
#include "scfloam/eval/rpe.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

struct EvalReport {
  std::size_t frames = 0;  // associated pose pairs evaluated
  KittiMetric kitti;
  AteResult ate;
  RpeResult rpe;
  // Provenance, shown in the table and JSON when set (eval fills them; run may leave them).
  std::string gt_name, est_name, association;
  std::size_t gt_total = 0, est_total = 0;
};

// gt and est are paired pose by pose (same length, KITTI camera-0 convention or both in one
// common convention). Throws scfloam::Error when they differ in length or are empty.
EvalReport evaluate_trajectory(const PoseList& gt, const PoseList& est);

// Human-readable table: per-length breakdown, t_err, r_err, ATE, RPE (several lines, each
// ending in '\n'). Undefined metrics print as "n/a" with the reason.
std::string format_eval_table(const EvalReport& report);

// One line of JSON (no trailing newline) with every figure; undefined numbers are null.
// Keys: frames, t_err_pct, r_err_deg_per_100m, kitti_segments, path_length_m, per_length[],
// ate_rmse_m, ate_mean_m, ate_median_m, ate_max_m, rpe_trans_rmse_m, rpe_trans_mean_m,
// rpe_rot_rmse_deg, rpe_rot_mean_deg, note, and gt, est, association, gt_poses, est_poses.
std::string eval_json(const EvalReport& report);

}  // namespace scfloam
