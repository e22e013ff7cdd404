// The paper's adaptive distance gate (eq. 1-3): a loop candidate is plausible only if, under
// the current poses, it lies within d_thre = base + k / n of the current keyframe, k being the
// number of keyframes so far, so the gate widens as odometry drift can grow. A fixed gate
// reproduces the baselines.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>

#include "scfloam/loop/config.hpp"

namespace scfloam {

class DistanceGate {
 public:
  static DistanceGate adaptive(double base_m, double keyframes_per_m);
  static DistanceGate fixed(double threshold_m);
  static DistanceGate from_config(const LoopDetectionConfig& config);

  // d_thre for a database of `keyframes` keyframes (the current one included).
  double threshold_m(std::size_t keyframes) const;
  bool accepts(double distance_m, std::size_t keyframes) const {
    return distance_m <= threshold_m(keyframes);
  }

  // d = |t(T_world_loop^-1 * T_world_current)|.
  static double distance_m(const Eigen::Isometry3d& T_world_loop,
                           const Eigen::Isometry3d& T_world_current);

 private:
  DistanceGate(bool adaptive, double base_m, double keyframes_per_m);
  bool adaptive_;
  double base_m_, keyframes_per_m_;
};

}  // namespace scfloam
