// Beam (ring) index of a return from its elevation angle, per sensor model.
#pragma once

#include <string>

namespace scfloam {

enum class LidarModel { hdl64, hdl32, vlp16, os1_64, os1_128 };

// "hdl64", "hdl32", "vlp16", "os1-64", "os1-128"; anything else throws scfloam::Error.
LidarModel parse_lidar_model(const std::string& name);
const char* lidar_model_name(LidarModel model);
int num_beams(LidarModel model);

// Ring in [0, num_beams) for an elevation in degrees, or -1 outside the sensor's field of view.
// HDL-64E follows F-LOAM's two-block table (upper block from +2 deg down to -8.83 deg at 1/3
// deg, lower block to -24.33 deg at 1/2 deg); the others are uniform fans (HDL-32E: -30.67 to
// +10.67 deg, VLP-16: -15 to +15 deg, OS1-64: +-16.6 deg, OS1-128: +-22.5 deg).
int ring_from_elevation_deg(LidarModel model, double elevation_deg);

}  // namespace scfloam
