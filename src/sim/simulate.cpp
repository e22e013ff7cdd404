// Writing a simulated sequence in the KITTI odometry layout.
#include "scfloam/sim/simulate.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "scfloam/atomic_file.hpp"
#include "scfloam/error.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "scfloam/io/trajectory.hpp"
#include "scfloam/progress.hpp"
#include "scfloam/sim/degenerate.hpp"
#include "scfloam/sim/scan.hpp"
#include "scfloam/stats.hpp"

namespace scfloam::sim {
namespace fs = std::filesystem;

SensorModel sensor_for(const SimConfig& config) {
  SensorModel s = sensor_preset(config.sensor);
  if (config.range_noise_m >= 0) s.range_noise_m = config.range_noise_m;
  if (config.dropout_prob >= 0) s.dropout_prob = config.dropout_prob;
  if (config.elevation_bias_deg > -90) s.elevation_bias_deg = config.elevation_bias_deg;
  if (config.beam_elevation_error_deg >= 0) s.beam_elevation_error_deg = config.beam_elevation_error_deg;
  if (config.beam_azimuth_error_deg >= 0) s.beam_azimuth_error_deg = config.beam_azimuth_error_deg;
  if (config.beam_range_bias_m >= 0) s.beam_range_bias_m = config.beam_range_bias_m;
  if (!std::isfinite(config.mount_roll_deg) || !std::isfinite(config.mount_pitch_deg) ||
      std::abs(config.mount_roll_deg) > 90 || std::abs(config.mount_pitch_deg) > 90)
    throw Error("simulate: the mount's roll and pitch must be within -90..90 degrees");
  s.mount_roll_deg = config.mount_roll_deg;
  s.mount_pitch_deg = config.mount_pitch_deg;
  return s;
}

namespace {
Scenario build_world_and_route(const SimConfig& config) {
  const double mount = sensor_for(config).mount_height_m;
  if (!config.scenario.empty()) return make_degenerate_scenario(config.scenario, config.seed, config.frames, mount);
  if (config.route == "loops") return make_loops_scenario(config.seed, config.frames, mount);
  if (config.route == "straight") return make_straight_scenario(config.seed, config.frames, mount);
  if (config.route == "kitti") {
    if (config.replay_poses.empty()) throw Error("route `kitti` needs a poses file (--kitti-poses FILE)");
    const PoseList cam = read_kitti_poses(config.replay_poses);
    if (cam.size() < 2) throw file_error(config.replay_poses, "needs at least 2 poses to replay");
    return make_replay_scenario(camera_to_lidar_poses(cam, kitti_default_Tr()), config.seed, config.frames, mount);
  }
  throw Error("unknown route `" + config.route + "` (known: loops, straight, kitti)");
}
}  // namespace

Scenario build_scenario(const SimConfig& config) {
  Scenario sc = build_world_and_route(config);
  sc.world.facade_detail = config.facade_detail;
  return sc;
}

double sweep_middle_after_stamp_s(const std::string& sweep_stamp, const SensorModel& sensor) {
  if (sweep_stamp == "middle") return 0;
  if (sweep_stamp == "start") return 0.5 * sensor.sweep_period_s;
  if (sweep_stamp == "end") return -0.5 * sensor.sweep_period_s;
  throw Error("simulate: sweep stamp \"" + sweep_stamp + "\" is not start, middle or end");
}

Scan render_frame(const Scenario& sc, const SensorModel& sensor, const BeamCalibration& calib,
                  const SimConfig& config, std::size_t k, const Traffic* traffic) {
  const double stamp = sc.frame_time(k);
  const double middle = stamp + sweep_middle_after_stamp_s(config.sweep_stamp, sensor);
  const auto at = [&](double t) { return sensor_pose_at(sc, sensor, t); };
  SweepPoses poses;
  poses.T_world_lidar = at(config.motion_distortion ? middle : stamp);
  poses.motion_distortion = config.motion_distortion;
  if (config.motion_distortion) {
    // The trajectory every hundredth of a second through the sweep (routes are sampled at
    // 100 Hz; a replay's 10 Hz poses are interpolated between).
    constexpr int kSteps = 10;
    for (int i = 0; i <= kSteps; ++i)
      poses.T_world_lidar_along.push_back(at(middle + (static_cast<double>(i) / kSteps - 0.5) * sensor.sweep_period_s));
  }
  Scan scan = render_scan(sc.world, sensor, calib, poses, config.seed, k, traffic, middle);
  // render_scan counts point times from the sweep's middle.
  if (middle != stamp) {
    const auto shift = static_cast<float>(middle - stamp);
    for (LidarPoint& p : scan.points) p.time_s += shift;
  }
  scan.timestamp_s = stamp;
  return scan;
}

Pose sensor_pose_at(const Scenario& sc, const SensorModel& sensor, double t) {
  Pose T = sc.trajectory.at(t);
  T.linear() = T.linear() * sensor.mount_rotation();
  return T;
}

PoseList relative_lidar_poses(const Scenario& sc, const SensorModel& sensor) {
  PoseList out;
  const Pose T0_inv = sensor_pose_at(sc, sensor, sc.frame_time(0)).inverse();
  for (std::size_t k = 0; k < sc.frames; ++k) out.push_back(T0_inv * sensor_pose_at(sc, sensor, sc.frame_time(k)));
  return out;
}

void simulate_sequence(const SimConfig& config, const fs::path& out_dir, bool progress) {
  if (config.scan_format != "bin" && config.scan_format != "pcd")
    throw Error("simulate: scan format \"" + config.scan_format + "\" is not bin or pcd");
  const bool pcd = config.scan_format == "pcd";
  Stopwatch clock;
  const SensorModel sensor = sensor_for(config);
  sweep_middle_after_stamp_s(config.sweep_stamp, sensor);  // a bad name fails before any work
  const Scenario sc = build_scenario(config);
  const double world_ms = clock.elapsed_ms();
  const BeamCalibration calib = draw_beam_calibration(sensor, config.seed);
  const Traffic traffic(sc.trajectory, sc.world, config.traffic, config.seed);
  std::error_code ec;
  fs::create_directories(out_dir / "velodyne", ec);
  if (ec) throw file_error(out_dir, "cannot create the output directory: " + ec.message());
  // Writing over an earlier sequence (--force): its scans go first, or a longer run or the
  // other scan format would leave scans that times.txt and poses.txt do not count.
  for (const auto& entry : fs::directory_iterator(out_dir / "velodyne")) {
    const fs::path& path = entry.path();
    if (entry.is_regular_file() && (path.extension() == ".bin" || path.extension() == ".pcd")) {
      fs::remove(path, ec);
      if (ec) throw file_error(path, "cannot remove the earlier scan: " + ec.message());
    }
  }

  ProgressBar bar("simulate", sc.frames, progress);
  std::size_t total_points = 0, movers_within_50m = 0;
  for (std::size_t k = 0; k < sc.frames; ++k) {
    const double t = sc.frame_time(k);
    Scan scan = render_frame(sc, sensor, calib, config, k, config.traffic.enabled ? &traffic : nullptr);
    apply_beam_losses(sc, k, sensor.beams(), &scan);
    movers_within_50m += traffic.count_near(t, sc.trajectory.at(t).translation().head<2>(), 50);
    total_points += scan.points.size();
    char name[32];
    std::snprintf(name, sizeof name, "%06zu.%s", k, pcd ? "pcd" : "bin");
    if (pcd) write_pcd(out_dir / "velodyne" / name, scan.points, PcdEncoding::kBinary, /*with_ring_time=*/true);
    else write_kitti_bin(out_dir / "velodyne" / name, scan.points);
    char note[64];
    std::snprintf(note, sizeof note, "%.1f ms/frame", clock.elapsed_ms() / (k + 1));
    bar.update(k + 1, note);
  }
  bar.finish();

  const Eigen::Isometry3d Tr = kitti_default_Tr();
  write_kitti_calib(out_dir / "calib.txt", Tr);
  write_file_atomic(out_dir / "times.txt", [&](std::ostream& out) {
    char buf[32];
    for (std::size_t k = 0; k < sc.frames; ++k) {
      std::snprintf(buf, sizeof buf, "%e\n", sc.frame_time(k));
      out << buf;
    }
  });
  write_kitti_poses(out_dir / "poses.txt", lidar_to_camera_poses(relative_lidar_poses(sc, sensor), Tr));
  write_file_atomic(out_dir / "sim.yaml", [&](std::ostream& out) {
    out << "# scfloam simulate: the parameters that made this sequence\n";
    out << "seed: " << config.seed << "\n";
    out << "frames: " << sc.frames << "\n";
    out << "route: " << config.route << "\n";
    if (!config.scenario.empty())
      out << "scenario: " << config.scenario << "\ndegenerate_frames: [" << sc.degenerate_first_frame << ", "
          << sc.degenerate_end_frame << "]  # [first, end)\n";
    if (config.route == "kitti") out << "replay_poses: \"" << config.replay_poses.string() << "\"\n";
    out << "description: \"" << sc.description << "\"\n";
    out << "route_length_m: " << sc.route_length_m << "\n";
    out << "sensor: " << sensor.name << "\n";
    out << "beams: " << sensor.beams() << "\n";
    out << "columns: " << sensor.columns << "\n";
    out << "max_range_m: " << sensor.max_range_m << "\n";
    out << "min_range_m: " << sensor.min_range_m << "\n";
    out << "mount_height_m: " << sensor.mount_height_m << "\n";
    out << "mount_roll_deg: " << sensor.mount_roll_deg << "\n";
    out << "mount_pitch_deg: " << sensor.mount_pitch_deg << "\n";
    out << "range_noise_m: " << sensor.range_noise_m << "\n";
    out << "dropout_prob: " << sensor.dropout_prob << "\n";
    out << "elevation_bias_deg: " << sensor.elevation_bias_deg << "\n";
    out << "beam_elevation_error_deg: " << sensor.beam_elevation_error_deg << "\n";
    out << "beam_azimuth_error_deg: " << sensor.beam_azimuth_error_deg << "\n";
    out << "beam_range_bias_m: " << sensor.beam_range_bias_m << "\n";
    out << "motion_distortion: " << (config.motion_distortion ? "true" : "false") << "\n";
    out << "scan_format: " << config.scan_format << "\n";
    out << "sweep_stamp: " << config.sweep_stamp << "\n";
    out << "world:\n  primitives: " << sc.world.primitives.size() << "\n  buildings: " << sc.stats.buildings
        << "\n  trees: " << sc.stats.trees << "\n  poles: " << sc.stats.poles << "\n  cars: " << sc.stats.cars
        << "\n  signs: " << sc.stats.signs << "\n";
    out << "facade_detail: " << (config.facade_detail ? "true" : "false") << "\n";
    out << "traffic:\n  enabled: " << (config.traffic.enabled ? "true" : "false")
        << "\n  oncoming_per_minute: " << config.traffic.oncoming_per_minute
        << "\n  leader_fraction: " << config.traffic.leader_fraction
        << "\n  follower_fraction: " << config.traffic.follower_fraction
        << "\n  pedestrians_per_minute: " << config.traffic.pedestrians_per_minute
        << "\n  movers: " << traffic.movers().size()
        << "\n  mean_movers_within_50m: " << (sc.frames ? double(movers_within_50m) / sc.frames : 0.0) << "\n";
    out << "mean_points_per_scan: " << (sc.frames ? total_points / sc.frames : 0) << "\n";
    // The errors drawn, beam by beam in the order of the sensor's elevations: the ground truth
    // of a calibration (elevation offsets include elevation_bias_deg).
    const auto list = [&](const char* name, const std::vector<double>& v, double scale) {
      out << "  " << name << ": [";
      for (std::size_t b = 0; b < v.size(); ++b) out << (b ? ", " : "") << v[b] * scale;
      out << "]\n";
    };
    out << "# true elevation / azimuth = nominal + offset; reported range = true range + bias\n";
    out << "beam_calibration:\n";
    list("elevation_deg", sensor.elevations_deg, 1.0);
    list("elevation_offset_deg", calib.elevation_offset_rad, 180.0 / M_PI);
    list("azimuth_offset_deg", calib.azimuth_offset_rad, 180.0 / M_PI);
    list("range_bias_m", calib.range_bias_m, 1.0);
  });
  if (progress)
    std::fprintf(stderr, "simulate: %zu frames, %.0f m, world %.1f s, total %.1f s, %zu points/scan -> %s\n",
                 sc.frames, sc.route_length_m, world_ms / 1000, clock.elapsed_ms() / 1000,
                 sc.frames ? total_points / sc.frames : 0, out_dir.string().c_str());
}

}  // namespace scfloam::sim
