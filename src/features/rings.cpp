#include "scfloam/features/rings.hpp"

#include <cmath>

#include "scfloam/error.hpp"

namespace scfloam {
namespace {

struct Fan {
  double lowest_deg, highest_deg;
  int beams;
};

Fan fan_of(LidarModel m) {
  switch (m) {
    case LidarModel::hdl32: return {-30.67, 10.67, 32};
    case LidarModel::vlp16: return {-15.0, 15.0, 16};
    case LidarModel::os1_64: return {-16.6, 16.6, 64};
    case LidarModel::os1_128: return {-22.5, 22.5, 128};
    case LidarModel::hdl64: break;
  }
  return {-24.33, 2.0, 64};
}

}  // namespace

LidarModel parse_lidar_model(const std::string& name) {
  if (name == "hdl64") return LidarModel::hdl64;
  if (name == "hdl32") return LidarModel::hdl32;
  if (name == "vlp16") return LidarModel::vlp16;
  if (name == "os1-64") return LidarModel::os1_64;
  if (name == "os1-128") return LidarModel::os1_128;
  throw Error("unknown lidar model `" + name +
              "` (expected hdl64, hdl32, vlp16, os1-64 or os1-128)");
}

const char* lidar_model_name(LidarModel model) {
  switch (model) {
    case LidarModel::hdl64: return "hdl64";
    case LidarModel::hdl32: return "hdl32";
    case LidarModel::vlp16: return "vlp16";
    case LidarModel::os1_64: return "os1-64";
    case LidarModel::os1_128: return "os1-128";
  }
  return "?";
}

int num_beams(LidarModel model) { return fan_of(model).beams; }

int ring_from_elevation_deg(LidarModel model, double a) {
  if (model == LidarModel::hdl64) {
    if (a > 2.0 || a < -24.33) return -1;
    const int ring = a >= -8.83 ? static_cast<int>((2.0 - a) * 3.0 + 0.5)
                                : 32 + static_cast<int>((-8.83 - a) * 2.0 + 0.5);
    return ring >= 0 && ring < 64 ? ring : -1;
  }
  // Uniform fan, ring 0 = lowest beam; half a spacing of tolerance beyond either end.
  const Fan f = fan_of(model);
  const double spacing = (f.highest_deg - f.lowest_deg) / (f.beams - 1);
  const double pos = (a - f.lowest_deg) / spacing;
  if (pos < -0.5 || pos >= f.beams - 0.5) return -1;
  return static_cast<int>(std::floor(pos + 0.5));
}

}  // namespace scfloam
