// Rendering one LiDAR sweep from the world: one ray per (column, beam), with range noise,
// per-beam calibration error, dropouts, reflectance and optional motion distortion.
#pragma once

#include <cstdint>
#include <vector>

#include "scfloam/sim/sensor.hpp"
#include "scfloam/sim/traffic.hpp"
#include "scfloam/sim/world.hpp"
#include "scfloam/types.hpp"

namespace scfloam::sim {

struct SweepPoses {
  Pose T_world_lidar;  // at the scan timestamp (mid-sweep, lidar facing forward)
  // Off: every column is cast from T_world_lidar (a motion-compensated scan, as KITTI's).
  // On: column c is cast from T_world_lidar_along (two or more poses, evenly spaced from the
  // sweep's start to its end) interpolated piecewise at (c + 0.5) / columns, and its points are
  // reported in that moving frame, uncompensated, as a raw sensor does. render_frame samples
  // the trajectory every 10 ms: two poses only (a chord from start to end) would miss the
  // sweep's middle pose by a quarter of the motion's second difference over the sweep (0.6 deg
  // for a hand-held sensor pitching 8 deg at 0.9 Hz).
  bool motion_distortion = false;
  std::vector<Pose> T_world_lidar_along;
};

// Renders one sweep. The sweep starts and ends behind the car (azimuth 180 deg) and turns
// clockwise seen from above, like a Velodyne; point time_s is the column time relative to the
// scan timestamp (-period/2 .. +period/2). Points are ordered ring by ring (ring 0 = top beam),
// each ring in firing order. Deterministic in (seed, frame) whatever the thread count.
// With `traffic`, its movers are placed at scan_time_s + point time (seconds on the
// trajectory's clock) column by column; without it the scene is the static world.
Scan render_scan(const World& world, const SensorModel& sensor, const BeamCalibration& calib,
                 const SweepPoses& poses, std::uint64_t seed, std::uint64_t frame,
                 const Traffic* traffic = nullptr, double scan_time_s = 0);

}  // namespace scfloam::sim
