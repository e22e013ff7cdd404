// Beam layouts of the supported sensors (datasheet values) and per-beam calibration errors.
#include "scfloam/sim/sensor.hpp"

#include <cmath>

#include "scfloam/error.hpp"
#include "scfloam/sim/rng.hpp"

namespace scfloam::sim {
namespace {
std::vector<double> linear_beams(double top_deg, double bottom_deg, int count) {
  std::vector<double> out(count);
  for (int i = 0; i < count; ++i)
    out[i] = count == 1 ? top_deg : top_deg + (bottom_deg - top_deg) * i / (count - 1);
  return out;
}
}  // namespace

Eigen::Matrix3d SensorModel::mount_rotation() const {
  const double d = M_PI / 180.0;
  return (Eigen::AngleAxisd(mount_pitch_deg * d, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(mount_roll_deg * d, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

std::vector<std::string> sensor_preset_names() {
  return {"hdl64", "vlp16", "hdl32", "os1-64", "os1-128", "vlp32c"};
}

SensorModel sensor_preset(const std::string& name) {
  SensorModel s;
  s.name = name;
  if (name == "hdl64") {
    // Two laser blocks: the upper 32 at ~1/3 deg from +2 deg, the lower 32 at ~1/2 deg to -24.9.
    s.elevations_deg = linear_beams(2.0, 2.0 - 31.0 / 3.0, 32);
    const auto lower = linear_beams(-8.87, -24.9, 32);
    s.elevations_deg.insert(s.elevations_deg.end(), lower.begin(), lower.end());
    s.columns = 2083;  // 0.1728 deg at 10 Hz
    s.max_range_m = 120;
    s.elevation_bias_deg = 0.205;  // KITTI's published scans
  } else if (name == "vlp16") {
    s.elevations_deg = linear_beams(15.0, -15.0, 16);
    s.columns = 1800;  // 0.2 deg
    s.max_range_m = 100;
    s.range_noise_m = 0.03;
  } else if (name == "hdl32") {
    s.elevations_deg = linear_beams(10.67, -30.67, 32);
    s.columns = 2170;  // ~0.166 deg
    s.max_range_m = 100;
  } else if (name == "os1-64") {
    // Gen-1 OS1-64: 64 beams over 33.2 deg (0.53 deg apart), as in config/os1-64.yaml's rings.
    s.elevations_deg = linear_beams(16.6, -16.6, 64);
    s.columns = 1024;  // 1024 x 10 mode
    s.max_range_m = 120;
    s.range_noise_m = 0.03;
  } else if (name == "os1-128") {
    s.elevations_deg = linear_beams(22.5, -22.5, 128);
    s.columns = 1024;  // 1024 x 10 mode
    s.max_range_m = 120;
    s.range_noise_m = 0.03;
  } else if (name == "vlp32c") {
    // Velodyne VLP-32C (Ultra Puck): 32 beams from +15 to -25 deg, dense around the horizon
    // (1/3 deg from +1.67 to -4.67) and sparse above and below. No built-in ring table of the
    // odometry matches it: it exercises rings learned from the scans (beam_layout.hpp).
    s.elevations_deg = {15.0,   10.333, 7.0,    4.667,  3.333,  2.333,  1.667,  1.333,
                        1.0,    0.667,  0.333,  0.0,    -0.333, -0.667, -1.0,   -1.333,
                        -1.667, -2.0,   -2.333, -2.667, -3.0,   -3.333, -3.667, -4.0,
                        -4.667, -5.333, -6.148, -7.254, -8.843, -11.31, -15.639, -25.0};
    s.columns = 1800;  // 0.2 deg at 10 Hz
    s.max_range_m = 120;
    s.range_noise_m = 0.03;
  } else {
    std::string known;
    for (const auto& n : sensor_preset_names()) known += (known.empty() ? "" : ", ") + n;
    throw Error("unknown sensor `" + name + "` (known: " + known + ")");
  }
  return s;
}

BeamCalibration draw_beam_calibration(const SensorModel& sensor, std::uint64_t seed) {
  Rng rng(hash_combine(seed, 0xCA11B7A7E5ULL));
  constexpr double kDeg = M_PI / 180.0;
  BeamCalibration c;
  for (int b = 0; b < sensor.beams(); ++b) {
    c.elevation_offset_rad.push_back((rng.normal(0, sensor.beam_elevation_error_deg) + sensor.elevation_bias_deg) * kDeg);
    c.azimuth_offset_rad.push_back(rng.normal(0, sensor.beam_azimuth_error_deg) * kDeg);
    c.range_bias_m.push_back(rng.normal(0, sensor.beam_range_bias_m));
  }
  return c;
}

}  // namespace scfloam::sim
