// Plain data that flows between the stages: points, scans, poses.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace scfloam {

// One LiDAR return in the sensor frame. `time_s` is relative to the scan's timestamp
// (0 when the source has no per-point time); `ring` is the beam index, -1 when unknown.
struct LidarPoint {
  float x = 0, y = 0, z = 0;
  float intensity = 0;
  float time_s = 0;
  std::int16_t ring = -1;
};

// Whether a value read as double can be stored in a LidarPoint's float: false for NaN,
// infinities and finite doubles beyond float's range (which would become inf).
inline bool fits_float(double v) { return std::abs(v) <= std::numeric_limits<float>::max(); }

// A ring field's value as a LidarPoint ring: NaN is "no ring" (-1), values outside -1..32767
// are clamped (a plain cast of them would be undefined behaviour).
inline std::int16_t ring_from_value(double v) {
  if (std::isnan(v)) return -1;
  return static_cast<std::int16_t>(v < -1.0 ? -1.0 : v > 32767.0 ? 32767.0 : v);
}

struct Scan {
  double timestamp_s = 0;
  std::vector<LidarPoint> points;
  bool has_ring = false;  // every point's ring came from the source
  bool has_time = false;  // every point's time_s came from the source
};

// Rigid transforms are named for their frames: T_world_lidar maps lidar coordinates to world.
using Pose = Eigen::Isometry3d;
using PoseList = std::vector<Eigen::Isometry3d>;  // C++17 aligned new makes this safe

// Feature points (edges or planes) of one frame, lidar frame unless a name says otherwise.
using FeatureCloud = std::vector<Eigen::Vector3f>;

}  // namespace scfloam
