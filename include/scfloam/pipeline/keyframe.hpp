// A keyframe as the stages share it: made by the odometry, immutable afterwards.
#pragma once

#include <Eigen/Geometry>
#include <memory>

#include "scfloam/types.hpp"

namespace scfloam {

struct Keyframe {
  std::size_t index = 0;  // keyframe number
  std::size_t frame = 0;  // scan number in the input
  Eigen::Isometry3d T_prev_current = Eigen::Isometry3d::Identity();  // odometry since previous kf
  FeatureCloud edges, planes;  // lidar frame
  FeatureCloud raw;            // downsampled raw scan (baseline descriptor and ICP), may be empty
};
using KeyframePtr = std::shared_ptr<const Keyframe>;

}  // namespace scfloam
