// Online estimate of the LiDAR's common elevation offset (all beams pointing higher or lower
// than their table says, as KITTI's HDL-64E does by ~0.2 deg). An uncorrected offset turns
// flat ground into a shallow cone around the sensor; matched against a map of cones seen from
// earlier poses it becomes a steady pitch drift (docs/odometry.md, step 3 and "Session 20").
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "scfloam/registration/feature_costs.hpp"

namespace scfloam {

struct ElevationStep {
  // The elevation correction (radians, added to the current one) that best explains the plane
  // matches on top of the solved pose; 0 when nothing constrains it.
  double step_rad = 0;
  // Its information (inverse variance per unit residual variance), after removing what a pose
  // change could explain: 0 when unobservable.
  double information = 0;
};

// Joint Gauss-Newton step of [pose; elevation correction] from a solved pose, where the
// pose's own gradient is zero: the correction's Schur complement, with a Huber weight on the
// residuals (`huber_m`). Points are in the lidar frame after the current correction.
ElevationStep elevation_step(const std::vector<PlaneMatch>& matches,
                             const Eigen::Isometry3d& T_world_lidar, double huber_m);

// Follows the offset frame by frame. The map the frame matched was built from earlier frames
// with the same error, so one frame sees only a fraction of the offset (~1/20 on a 64-beam
// city drive): the estimate converges over the map's turnover, ~100-200 frames, not at once.
class ElevationCalibration {
 public:
  // `initial_deg`: the configured correction; the estimate stays within `max_change_deg` of it.
  ElevationCalibration(double initial_deg, double gain, double max_change_deg);

  // Updates from one solved frame; returns the correction for the next frame's features.
  double update(const std::vector<PlaneMatch>& matches, const Eigen::Isometry3d& T_world_lidar);
  double correction_deg() const { return correction_deg_; }

 private:
  double initial_deg_, gain_, max_change_deg_;
  double correction_deg_;
};

}  // namespace scfloam
