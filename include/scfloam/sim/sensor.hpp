// Spinning multi-beam LiDAR models: beam layout, range limits, noise and per-beam
// calibration errors, with presets for the common sensors.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace scfloam::sim {

struct SensorModel {
  std::string name;
  // Nominal beam elevations in degrees, index = ring; ring 0 is the highest beam.
  std::vector<double> elevations_deg;
  int columns = 2083;            // firings per revolution (azimuth step = 360 / columns)
  double sweep_period_s = 0.1;   // one revolution (10 Hz)
  double max_range_m = 120.0;    // no return beyond this (and none from the sky)
  double min_range_m = 2.5;      // returns from the ego car / closer than this are dropped
  double mount_height_m = 1.73;  // sensor origin above the road
  // The sensor's tilt on the vehicle (degrees): many robots and hand-held rigs tilt their LiDAR
  // to see the ground near by. The sensor frame is the vehicle frame rotated by
  // Ry(pitch) * Rx(roll) at the mount point (roll about the vehicle's forward x, then pitch
  // about its fixed left y): positive pitch looks down ahead, positive roll lifts the sensor's
  // left side. Scans and poses.txt are in the tilted sensor frame.
  double mount_roll_deg = 0;
  double mount_pitch_deg = 0;
  double range_noise_m = 0.02;   // gaussian, per return
  double dropout_prob = 0.02;    // random missing returns (plus more at grazing incidence)
  // Residual calibration errors drawn once per sequence (1 sigma): real sensors are
  // calibrated to about this, and their points inherit it.
  double beam_elevation_error_deg = 0.02;
  double beam_azimuth_error_deg = 0.02;
  double beam_range_bias_m = 0.008;
  // A common error of all beams' elevation (true = nominal + bias), as in KITTI's scans,
  // whose points are commonly corrected by raising them ~0.2 deg (IMLS-SLAM, CT-ICP): the
  // ground becomes a shallow cone, heights err by range x bias.
  double elevation_bias_deg = 0;

  // Rotation from the sensor frame to the vehicle frame: Ry(pitch) * Rx(roll).
  Eigen::Matrix3d mount_rotation() const;

  double azimuth_step_deg() const { return 360.0 / columns; }
  int beams() const { return static_cast<int>(elevations_deg.size()); }
};

// "hdl64" (Velodyne HDL-64E, KITTI), "vlp16", "hdl32", "os1-64", "os1-128". Throws scfloam::Error
// listing the known names for anything else.
SensorModel sensor_preset(const std::string& name);
std::vector<std::string> sensor_preset_names();

// Per-beam calibration errors of one physical sensor instance, drawn from `seed`.
struct BeamCalibration {
  std::vector<double> elevation_offset_rad, azimuth_offset_rad, range_bias_m;
};
BeamCalibration draw_beam_calibration(const SensorModel& sensor, std::uint64_t seed);

}  // namespace scfloam::sim
