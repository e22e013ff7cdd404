// Driving routes: a smooth, physical car trajectory (speed 5-12 m/s, bounded acceleration
// and yaw rate, roll/pitch from the terrain and the suspension) along a planned street path.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <vector>

#include "scfloam/types.hpp"

namespace scfloam::sim {

// Lidar poses sampled at a fixed rate from t = 0; at() interpolates (SE(3)).
struct SampledTrajectory {
  double dt_s = 0.01;
  PoseList T_world_lidar;
  // Between samples: false, along the straight screw between the two (fine for 100 Hz
  // routes); true, along a cubic through the neighbouring samples as well (Catmull-Rom in the
  // earlier sample's tangent space), so that a trajectory sampled at the frame rate (a replay)
  // changes speed and turn rate smoothly within a sweep instead of at each sample.
  bool smooth = false;
  Pose at(double t_s) const;
  double duration_s() const { return T_world_lidar.empty() ? 0 : (T_world_lidar.size() - 1) * dt_s; }
};

struct DriveLimits {
  double min_speed_mps = 5.0, max_speed_mps = 12.0;
  double max_accel_mps2 = 1.5;    // longitudinal, both ways
  double max_lateral_mps2 = 2.5;  // slows the car in turns (never below min_speed)
  double mount_height_m = 1.73;
};

// Drives a 2D path (any polyline along street centerlines, already offset to a lane) for
// `duration_s`, sampling poses every dt_s. The path is smoothed (corners become curves);
// the speed follows a smooth random profile, limited by curvature and acceleration; z,
// roll and pitch follow `ground_height` (with its slope) plus small suspension motion.
SampledTrajectory drive_path(const std::vector<Eigen::Vector2d>& path, double duration_s,
                             const std::function<double(double, double)>& ground_height,
                             const DriveLimits& limits, std::uint64_t seed, double dt_s = 0.01);

// Smooths a polyline: resample every `step_m` then gaussian-filter positions (sigma_m).
std::vector<Eigen::Vector2d> smooth_path(const std::vector<Eigen::Vector2d>& path, double step_m,
                                         double sigma_m);
// Offsets a smooth path sideways (positive = to the right of the travel direction).
std::vector<Eigen::Vector2d> offset_path(const std::vector<Eigen::Vector2d>& path, double right_m);

}  // namespace scfloam::sim
