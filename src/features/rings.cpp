#include "scfloam/features/rings.hpp"

#include <cmath>

#include "scfloam/error.hpp"

namespace scfloam {

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

int num_beams(LidarModel model) { return beam_fan(model).beams; }

}  // namespace scfloam
