// Beam (ring) index of a return from its elevation angle, per sensor model.
#pragma once

#include <cmath>
#include <string>

namespace scfloam {

enum class LidarModel { hdl64, hdl32, vlp16, os1_64, os1_128 };

// "hdl64", "hdl32", "vlp16", "os1-64", "os1-128"; anything else throws scfloam::Error.
LidarModel parse_lidar_model(const std::string& name);
const char* lidar_model_name(LidarModel model);
int num_beams(LidarModel model);

// The angular fan of a uniform-fan model (every model but hdl64).
struct BeamFan {
  double lowest_deg, highest_deg;
  int beams;
};
inline BeamFan beam_fan(LidarModel m) {
  switch (m) {
    case LidarModel::hdl32: return {-30.67, 10.67, 32};
    case LidarModel::vlp16: return {-15.0, 15.0, 16};
    case LidarModel::os1_64: return {-16.6, 16.6, 64};
    case LidarModel::os1_128: return {-22.5, 22.5, 128};
    case LidarModel::hdl64: break;
  }
  return {-24.33, 2.0, 64};
}

// Ring in [0, num_beams) for an elevation in degrees, or -1 outside the sensor's field of view.
// HDL-64E follows F-LOAM's two-block table (upper block from +2 deg down to -8.83 deg at 1/3
// deg, lower block to -24.33 deg at 1/2 deg); the others are uniform fans (HDL-32E: -30.67 to
// +10.67 deg, VLP-16: -15 to +15 deg, OS1-64: +-16.6 deg, OS1-128: +-22.5 deg).
// Inline: it runs once per input point (~120k per frame).
inline int ring_from_elevation_deg(LidarModel model, double a) {
  if (model == LidarModel::hdl64) {
    if (a > 2.0 || a < -24.33) return -1;
    const int ring = a >= -8.83 ? static_cast<int>((2.0 - a) * 3.0 + 0.5)
                                : 32 + static_cast<int>((-8.83 - a) * 2.0 + 0.5);
    return ring >= 0 && ring < 64 ? ring : -1;
  }
  // Uniform fan, ring 0 = lowest beam; half a spacing of tolerance beyond either end.
  const BeamFan f = beam_fan(model);
  const double spacing = (f.highest_deg - f.lowest_deg) / (f.beams - 1);
  const double pos = (a - f.lowest_deg) / spacing;
  if (pos < -0.5 || pos >= f.beams - 0.5) return -1;
  return static_cast<int>(std::floor(pos + 0.5));
}

// ring_from_elevation_deg's HDL-64E table in float arithmetic, for the feature step: the SSE2
// lanes of its ring assignment do these same float operations in this order, so a point gets
// the same ring in a lane or in the scalar tail. It differs from the double version only for
// elevations within float rounding (~1e-6 deg) of a boundary between two beams.
inline int ring_from_elevation_hdl64_deg(float a) {
  if (a > 2.0f || a < -24.33f) return -1;
  const int ring = a >= -8.83f ? static_cast<int>((2.0f - a) * 3.0f + 0.5f)
                               : 32 + static_cast<int>((-8.83f - a) * 2.0f + 0.5f);
  return ring >= 0 && ring < 64 ? ring : -1;
}

}  // namespace scfloam
