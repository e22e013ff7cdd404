// `scfloam simulate`: a whole KITTI odometry sequence from a scenario.
//
//   SimConfig cfg;  cfg.frames = 200;  cfg.route = "loops";
//   simulate_sequence(cfg, "/tmp/seq", /*progress=*/false);
//   auto seq = KittiSequence::open("/tmp/seq");   // velodyne/, calib.txt, times.txt, poses.txt
//
// In memory (tests): auto sc = build_scenario(cfg); then render_scan(sc.world, ...) per pose.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "scfloam/sim/scan.hpp"
#include "scfloam/sim/scenario.hpp"
#include "scfloam/sim/sensor.hpp"
#include "scfloam/sim/traffic.hpp"

namespace scfloam::sim {

struct SimConfig {
  std::uint64_t seed = 1;
  std::size_t frames = 1000;      // replay: 0 = every pose of the file
  std::string route = "loops";    // "loops", "straight" or "kitti" (replay)
  // A degenerate scene instead of the route (degenerate.hpp: "tunnel", "gap", ...);
  // frames = 0 then gives the scene's natural length.
  std::string scenario;
  std::filesystem::path replay_poses;  // KITTI camera-0 poses file for route "kitti"
  std::string sensor = "hdl64";   // see sensor_preset_names()
  bool motion_distortion = false;  // KITTI's own scans are already compensated
  // velodyne/ as KITTI's "bin" (x y z reflectance), or "pcd" (binary PCD with ring and
  // per-point time, seconds from the frame's stamp): what deskew needs on distorted scans.
  std::string scan_format = "bin";
  // Where in its sweep a scan is stamped: "middle" (KITTI; the sweep spans stamp -/+ 0.05 s),
  // "start" (Ouster, Hesai: stamp ... stamp + 0.1 s) or "end" (Velodyne's ROS driver). Point
  // times count from the stamp, poses.txt is the sensor at the stamp, and a compensated scan
  // (no motion_distortion) is in the sensor frame at the stamp.
  std::string sweep_stamp = "middle";
  // Overrides of the preset's noise (negative = keep the preset's value).
  double range_noise_m = -1;
  double dropout_prob = -1;
  double elevation_bias_deg = -1e9;  // below -90: keep the preset's (hdl64: KITTI's 0.205)
  // Per-beam calibration errors, 1 sigma (negative = the preset's: 0.02 deg, 0.02 deg, 8 mm).
  double beam_elevation_error_deg = -1;
  double beam_azimuth_error_deg = -1;
  double beam_range_bias_m = -1;
  // The sensor's tilt on the vehicle (SensorModel::mount_roll_deg / mount_pitch_deg).
  double mount_roll_deg = 0;
  double mount_pitch_deg = 0;
  TrafficConfig traffic;  // moving cars and pedestrians (on by default)
  bool facade_detail = true;  // recessed windows, ledges, glass on building walls
};

SensorModel sensor_for(const SimConfig& config);
// World + trajectory for the config (throws scfloam::Error for a bad route or poses file).
Scenario build_scenario(const SimConfig& config);

// The middle of a sweep minus its stamp: 0, +period/2 ("start") or -period/2 ("end"); throws
// scfloam::Error for another name.
double sweep_middle_after_stamp_s(const std::string& sweep_stamp, const SensorModel& sensor);

// Frame k of the scenario as the sensor reports it: stamped at sc.frame_time(k), the sweep
// where config.sweep_stamp puts it (cast along it with config.motion_distortion), point times
// from the stamp. Beam losses of degenerate scenes are not applied (simulate_sequence does).
Scan render_frame(const Scenario& sc, const SensorModel& sensor, const BeamCalibration& calib,
                  const SimConfig& config, std::size_t k, const Traffic* traffic = nullptr);

// Writes velodyne/NNNNNN.bin, calib.txt (KITTI's Tr), times.txt (10 Hz), poses.txt (camera-0
// ground truth, first pose identity) and sim.yaml (the parameters used) into out_dir, which
// is created if needed. Same config -> same bytes.
void simulate_sequence(const SimConfig& config, const std::filesystem::path& out_dir, bool progress);

// The sensor's pose at time t: the vehicle's (the scenario's trajectory) turned by the mount.
Pose sensor_pose_at(const Scenario& scenario, const SensorModel& sensor, double t);

// Ground-truth sensor poses relative to the first frame (what poses.txt encodes).
PoseList relative_lidar_poses(const Scenario& scenario, const SensorModel& sensor);

}  // namespace scfloam::sim
