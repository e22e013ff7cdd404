// `scfloam simulate`: write a simulated KITTI-layout sequence with ground truth.
#include <filesystem>

#include "command_registry.hpp"
#include "scfloam/error.hpp"
#include "scfloam/sim/degenerate.hpp"
#include "scfloam/sim/sensor.hpp"
#include "scfloam/sim/simulate.hpp"

namespace {
namespace fs = std::filesystem;

struct SimulateArgs {
  scfloam::sim::SimConfig config;
  fs::path out;
  fs::path replay;
  bool force = false;
  bool quiet = false;
  bool frames_given = false;
  bool no_traffic = false;
  bool plain_facades = false;
};

void run(SimulateArgs& a) {
  auto& cfg = a.config;
  if (a.no_traffic) cfg.traffic.enabled = false;
  if (a.plain_facades) cfg.facade_detail = false;
  if (cfg.traffic.oncoming_per_minute < 0 || cfg.traffic.pedestrians_per_minute < 0 ||
      cfg.traffic.leader_fraction < 0 || cfg.traffic.leader_fraction > 1 ||
      cfg.traffic.follower_fraction < 0 || cfg.traffic.follower_fraction > 1)
    throw scfloam::Error("traffic rates must be >= 0 and the leader/follower fractions within [0, 1]");
  if (!cfg.scenario.empty() && !a.replay.empty())
    throw scfloam::Error("--scenario builds its own scene: it cannot be combined with --kitti-poses/--replay");
  if (!a.replay.empty()) {
    if (cfg.route != "loops" && cfg.route != "kitti")
      throw scfloam::Error("--kitti-poses/--replay replays a trajectory: it cannot be combined with --route " + cfg.route);
    cfg.route = "kitti";
    cfg.replay_poses = a.replay;
  }
  if (cfg.route == "kitti" && cfg.replay_poses.empty())
    throw scfloam::Error("--route kitti needs --kitti-poses FILE");
  if (cfg.route == "kitti" && !a.frames_given) cfg.frames = 0;  // every pose of the file
  if (!cfg.scenario.empty() && !a.frames_given) cfg.frames = 0;  // the scene's natural length
  if (cfg.route != "kitti" && cfg.frames < 2 && !(cfg.scenario.size() && cfg.frames == 0))
    throw scfloam::Error("--frames must be at least 2");
  if (fs::exists(a.out)) {
    if (!fs::is_directory(a.out)) throw scfloam::file_error(a.out, "exists and is not a directory");
    if (!fs::is_empty(a.out) && !a.force)
      throw scfloam::file_error(a.out, "is not empty (use --force to write into it)");
  }
  scfloam::sim::simulate_sequence(cfg, a.out, !a.quiet);
}

scfloam::cli::RegisterCommand reg("simulate", [](CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  auto* sub = app.add_subcommand("simulate", "Simulate a LiDAR sequence in a procedural city (KITTI layout + ground truth)");
  sub->add_option("--out", args->out, "Output sequence directory")->required();
  sub->add_option("--frames", args->config.frames, "Number of scans (10 Hz); replay: at most this many")
      ->each([args](const std::string&) { args->frames_given = true; })
      ->capture_default_str();
  sub->add_option("--seed", args->config.seed, "World, route and noise seed")->capture_default_str();
  sub->add_option("--route", args->config.route, "loops | straight | kitti")
      ->check(CLI::IsMember({"loops", "straight", "kitti"}))->capture_default_str();
  sub->add_option("--scenario", args->config.scenario,
                  "A degenerate scene instead of --route (docs/degenerate.md); without --frames, its natural length")
      ->check(CLI::IsMember(scfloam::sim::degenerate_scenario_names()));
  sub->add_option("--kitti-poses,--replay", args->replay, "Replay this KITTI poses file (camera-0) through a city built around it")
      ->check(CLI::ExistingFile);
  sub->add_option("--sensor", args->config.sensor, "hdl64 | vlp16 | hdl32 | os1-64 | os1-128 | vlp32c")
      ->check(CLI::IsMember(scfloam::sim::sensor_preset_names()))->capture_default_str();
  sub->add_flag("--motion-distortion", args->config.motion_distortion, "Cast each column from the pose at its firing time");
  sub->add_option("--scan-format", args->config.scan_format,
                  "velodyne/ as KITTI .bin (x y z reflectance) or binary .pcd with ring and per-point time "
                  "(for deskew of --motion-distortion scans)")
      ->check(CLI::IsMember({"bin", "pcd"}))->capture_default_str();
  sub->add_option("--sweep-stamp", args->config.sweep_stamp,
                  "Where in its sweep a scan is stamped: middle (KITTI), start (Ouster, Hesai) or end (Velodyne's "
                  "ROS driver); point times count from it, poses.txt is the sensor there")
      ->check(CLI::IsMember({"start", "middle", "end"}))->capture_default_str();
  sub->add_option("--range-noise", args->config.range_noise_m, "Range noise sigma in metres (default: the sensor's)")
      ->check(CLI::Range(0.0, 1.0));
  sub->add_option("--dropout", args->config.dropout_prob, "Random dropout probability (default: the sensor's)")
      ->check(CLI::Range(0.0, 0.9));
  sub->add_option("--elevation-bias", args->config.elevation_bias_deg,
                  "Common elevation error of all beams in degrees (default: the sensor's; hdl64 0.205 as KITTI)");
  sub->add_option("--beam-elevation-error", args->config.beam_elevation_error_deg,
                  "Per-beam elevation calibration error, 1 sigma in degrees (default: the sensor's, 0.02)")
      ->check(CLI::Range(0.0, 5.0));
  sub->add_option("--beam-azimuth-error", args->config.beam_azimuth_error_deg,
                  "Per-beam azimuth calibration error, 1 sigma in degrees (default: the sensor's, 0.02)")
      ->check(CLI::Range(0.0, 5.0));
  sub->add_option("--beam-range-bias", args->config.beam_range_bias_m,
                  "Per-beam range bias, 1 sigma in metres (default: the sensor's, 0.008)")
      ->check(CLI::Range(0.0, 1.0));
  sub->add_option("--mount-pitch", args->config.mount_pitch_deg,
                  "The sensor's pitch on the vehicle in degrees, positive = tilted down ahead (default 0)")
      ->check(CLI::Range(-90.0, 90.0));
  sub->add_option("--mount-roll", args->config.mount_roll_deg,
                  "The sensor's roll on the vehicle in degrees, about the forward axis, positive = left side up (default 0)")
      ->check(CLI::Range(-90.0, 90.0));
  sub->add_flag("--no-traffic", args->no_traffic, "A static world: no moving cars or pedestrians");
  sub->add_option("--oncoming-per-min", args->config.traffic.oncoming_per_minute, "Oncoming cars passing per minute")
      ->capture_default_str();
  sub->add_option("--leader-fraction", args->config.traffic.leader_fraction, "Share of the time a car drives ahead in the ego lane")
      ->capture_default_str();
  sub->add_option("--follower-fraction", args->config.traffic.follower_fraction, "Share of the time a car follows in the ego lane")
      ->capture_default_str();
  sub->add_option("--pedestrians-per-min", args->config.traffic.pedestrians_per_minute, "Pedestrians appearing per minute")
      ->capture_default_str();
  sub->add_flag("--plain-facades", args->plain_facades, "Building walls as plain boxes (no windows, ledges or glass)");
  sub->add_flag("--force", args->force, "Write into a non-empty output directory");
  sub->add_flag("--quiet", args->quiet, "No progress bar");
  sub->callback([args] { run(*args); });
});

}  // namespace
