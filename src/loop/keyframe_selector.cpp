#include "scfloam/loop/keyframe_selector.hpp"

#include <string>

#include "scfloam/error.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {

KeyframeSelector::KeyframeSelector(double distance_m, double angle_rad)
    : distance_m_(distance_m), angle_rad_(angle_rad) {
  if (!(distance_m > 0.0) || !(angle_rad > 0.0))
    throw Error("keyframe selection: distance and angle thresholds must be positive (got " +
                std::to_string(distance_m) + " m, " + std::to_string(angle_rad) + " rad)");
}

bool KeyframeSelector::update(const Eigen::Isometry3d& T_world_lidar) {
  if (!has_previous_) {
    has_previous_ = true;
    T_world_previous_ = T_world_lidar;
    return true;
  }
  // Accumulated, not net, motion: turning back and forth still counts as rotation.
  const Eigen::Isometry3d T_previous_current = T_world_previous_.inverse() * T_world_lidar;
  travel_m_ += T_previous_current.translation().norm();
  rotation_rad_ += rotation_angle_rad(T_previous_current.linear());
  T_world_previous_ = T_world_lidar;
  if (travel_m_ >= distance_m_ || rotation_rad_ >= angle_rad_) {
    travel_m_ = 0.0;
    rotation_rad_ = 0.0;
    return true;
  }
  return false;
}

}  // namespace scfloam
