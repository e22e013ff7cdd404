// The LiDAR's common elevation offset estimated from the road. Beams that all point a little
// higher than their table says report flat ground as a shallow cone around the sensor: a point
// at horizontal range r appears r * offset too low, and matched against a map of such cones
// seen from earlier poses this becomes a steady pitch drift that no loop closure sees (the
// estimated world curves like a bowl). One scan shows the cone (fit_ground_cone), but a road
// that bends vertically looks the same; two scans of the same road from different places tell
// them apart (pair_equation). docs/odometry.md, "Session 25", has the measurements, including
// what the beams' own elevation errors do to the estimate.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include "scfloam/types.hpp"

namespace scfloam {

struct GroundConeFit {
  bool ok = false;        // false: too little clean ground ahead and behind, or too steep
  double slope_rad = 0;   // apparent rise of the ground per metre of range (-offset)
  double spread_m = 0;    // robust spread of the ground points about the fit
  int ahead = 0, behind = 0;  // ground points used on each side
  std::vector<Eigen::Vector3f> road;  // the points the fit kept (lidar frame), when ok
};

// Fits the ground in a band along `direction` (the driving direction, in the lidar frame's
// x-y plane; need not be unit length) through the sensor, within 3 m across and 5 to 40 m
// along, to z = a + b * along + c * across + slope * range: a pitch tilts the road ahead up
// and behind down, the cone lifts or lowers both alike. Its kept points are the scan's road.
GroundConeFit fit_ground_cone(const std::vector<LidarPoint>& points, const Eigen::Vector2d& direction);

// Follows the offset over a drive from pairs of scans 6-30 m apart. One scan's cone fit is
// confounded by the road's own vertical bends; two scans see the same road from different
// places, and where the later scan's road points, put into the earlier scan's frame with the
// odometry's relative pose, lie within 0.1 m of the earlier scan's, the height difference is
// the road (gone: the same spot) plus the relative pose's error (a constant and a tilt) plus
// the offset times the difference of the two ranges (ahead of both scans -distance, behind
// both +distance: a step no tilt makes). The pairs' least squares are pooled over the drive.
class GroundElevationEstimate {
 public:
  // `initial_deg`: the configured correction, used until `min_pairs` pairs have given a fit;
  // the estimate stays within `max_change_deg` of it.
  GroundElevationEstimate(double initial_deg, std::size_t min_pairs = 10, double max_change_deg = 1.0);

  // One solved frame: its raw points (before any correction), its pose, and its motion over
  // the last frame in its own frame (the band's direction; less than 0.2 m of horizontal
  // motion: not used). Returns the correction for the next frame's features.
  double update(const std::vector<LidarPoint>& points, const Eigen::Isometry3d& T_world_lidar,
                const Eigen::Vector3d& motion_lidar);
  double correction_deg() const { return correction_deg_; }
  std::size_t pairs_used() const { return pairs_; }

  struct Patch;  // one scan's road points and pose

 private:
  double initial_deg_, max_change_deg_;
  std::size_t min_pairs_;
  double correction_deg_;
  std::vector<std::shared_ptr<const Patch>> recent_;  // oldest first, within ~36 m
  std::size_t next_distance_ = 0;
  std::size_t pairs_ = 0;
  double information_ = 0, vector_ = 0;  // the pairs' pooled normal equation for the offset
};

// One pair's least-squares equation for the offset (radians; the correction that removes
// it), the relative pose's error eliminated: information * offset = vector.
struct GroundPairEquation {
  double information = 0, vector = 0;
  double offset_rad() const { return vector / information; }
};

// From two scans' road points (`fit_ground_cone`'s), `later` being the frame
// `T_earlier_later` in the earlier one's frame; nullopt when they do not share at least 100
// spots of road ahead of both and 100 behind both.
struct RoadGrid;
std::optional<GroundPairEquation> pair_equation(const RoadGrid& earlier, const std::vector<Eigen::Vector3f>& later,
                                                const Eigen::Isometry3d& T_earlier_later);
std::optional<double> offset_between(const std::vector<Eigen::Vector3f>& earlier,
                                     const std::vector<Eigen::Vector3f>& later,
                                     const Eigen::Isometry3d& T_earlier_later);

}  // namespace scfloam
