// Absolute trajectory error (ATE) after a rigid SE(3) Umeyama alignment of the estimate's
// positions onto the ground truth's (no scale: a LiDAR trajectory has metric scale).
#pragma once

#include <vector>

#include "scfloam/types.hpp"

namespace scfloam {

// The rigid transform T minimizing sum ||dst_i - T src_i||^2 (Umeyama 1991, without scale).
// Fewer than 3 points: translation only (rotation is not observable). Throws scfloam::Error on
// empty or mismatched input.
Pose umeyama_se3(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst);

struct AteResult {
  Pose T_gt_est = Pose::Identity();  // maps estimate world coordinates into the gt world
  PoseList aligned_est;              // T_gt_est * est[i]
  std::vector<double> errors_m;      // per frame: ||t(gt[i]) - t(aligned_est[i])||
  double rmse_m = 0, mean_m = 0, median_m = 0, max_m = 0;
};

AteResult absolute_trajectory_error(const PoseList& gt, const PoseList& est);

// Convenience: ATE RMSE in metres after SE(3) alignment.
double ate_rmse_m(const PoseList& gt, const PoseList& est);

}  // namespace scfloam
