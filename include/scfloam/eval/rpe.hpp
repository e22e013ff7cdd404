// Relative pose error (RPE) between consecutive frames: how wrong each frame-to-frame motion
// is, independent of drift accumulated before it.
#pragma once

#include <vector>

#include "scfloam/types.hpp"

namespace scfloam {

struct RpeResult {
  // Entry k compares the motion from frame k to frame k+1:
  // E = (gt[k]^-1 gt[k+1])^-1 (est[k]^-1 est[k+1]).
  std::vector<double> trans_m;   // ||t(E)||
  std::vector<double> rot_deg;   // angle(R(E))
  double trans_rmse_m = 0, trans_mean_m = 0;
  double rot_rmse_deg = 0, rot_mean_deg = 0;
  std::size_t pairs() const { return trans_m.size(); }
};

// Throws scfloam::Error on lists of different length. One pose gives zero pairs (all 0).
RpeResult relative_pose_error(const PoseList& gt, const PoseList& est);

}  // namespace scfloam
