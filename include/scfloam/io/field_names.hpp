// The per-point field names every point-cloud reader (PCD, PLY, ROS PointCloud2) looks for,
// in order of preference: the first present wins. One list, so that a scan exported from a
// bag to PCD reads as the bag did (docs/inputs.md, docs/bags.md).
#pragma once

#include <array>

namespace scfloam::field_names {

// VeloView exports `laser_id`, livox_ros_driver `line`; Ouster has `reflectivity` besides
// `intensity`.
inline constexpr std::array<const char*, 4> kIntensity = {"intensity", "reflectivity", "reflectance", "i"};
inline constexpr std::array<const char*, 4> kRing = {"ring", "channel", "laser_id", "line"};
inline constexpr std::array<const char*, 6> kTime = {"time", "t", "time_offset", "offset_time", "timestamp", "ts"};

}  // namespace scfloam::field_names
