// Decides which frames become keyframes: the first frame, then whenever the travel or the
// rotation accumulated frame by frame since the last keyframe reaches a threshold.
#pragma once

#include <Eigen/Geometry>

namespace scfloam {

class KeyframeSelector {
 public:
  KeyframeSelector(double distance_m, double angle_rad);

  // Feed every frame's pose in order; true when this frame is a new keyframe.
  bool update(const Eigen::Isometry3d& T_world_lidar);

  double travel_since_keyframe_m() const { return travel_m_; }
  double rotation_since_keyframe_rad() const { return rotation_rad_; }

 private:
  double distance_m_, angle_rad_;
  bool has_previous_ = false;
  Eigen::Isometry3d T_world_previous_ = Eigen::Isometry3d::Identity();
  double travel_m_ = 0.0, rotation_rad_ = 0.0;
};

}  // namespace scfloam
