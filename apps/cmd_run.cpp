// `scfloam run INPUT`: the whole system on a recorded sequence.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include "command_registry.hpp"
#include "interrupt.hpp"
#include "scfloam/error.hpp"
#include "scfloam/io/scan_source.hpp"
#include "scfloam/io/sensor_detection.hpp"
#include "scfloam/pipeline/outputs.hpp"
#include "scfloam/pipeline/pipeline.hpp"

namespace scfloam::cli {
namespace {

struct RunArgs {
  std::string input;
  std::string out_dir;
  std::string mode = "optimized";
  std::string config_file;
  std::string sensor;
  std::string topic;
  std::string timestamps;
  std::string frame = "auto";
  double map_voxel_m = 0.2;
  bool ply = false;
  bool save_keyframes = false;
  std::size_t frames = 0;
  bool force = false;
  bool quiet = false;
  bool deterministic = false;
};

// A setting check's verdict (summary.json's `deskew` or `elevation_check`), once decided:
// "deskew check: distorted (frame 19, 15 frames compared, deskewed / raw residual 0.80)".
void print_check(const char* name, const nlohmann::json& check, const char* ratio_name,
                 const char* switched_verdict, const char* switched_text) {
  if (!check.contains("decided_at_frame")) return;
  std::printf("%s: %s (frame %zu, %zu frames compared", name, check["check"].get<std::string>().c_str(),
              check["decided_at_frame"].get<std::size_t>(), check["frames_compared"].get<std::size_t>());
  if (check.contains("residual_ratio"))
    std::printf(", %s residual %.2f", ratio_name, check["residual_ratio"].get<double>());
  std::printf(")%s%s\n", check["check"] == switched_verdict ? ": " : "",
              check["check"] == switched_verdict ? switched_text : "");
}

void print_report(const nlohmann::json& summary) {
  std::printf("frames %zu, keyframes %zu, %.1f s wall, %.1f frames/s, peak memory %.0f MB\n",
              summary["frames"].get<std::size_t>(), summary["keyframes"].get<std::size_t>(),
              summary["wall_s"].get<double>(), summary["fps"].get<double>(),
              summary["peak_rss_mb"].get<double>());
  const auto& elevation = summary["elevation_correction_deg"];
  const auto& elevation_check = summary["elevation_check"];
  if (elevation["first_frame"].get<double>() != elevation["last_frame"].get<double>() &&
      elevation_check["check"] != "no offset")
    std::printf("elevation correction estimated online: %.3f deg at the first frame, %.3f deg at the last\n",
                elevation["first_frame"].get<double>(), elevation["last_frame"].get<double>());
  print_check("deskew check", summary["deskew"], "deskewed / raw", "compensated",
              "the scans are already motion-compensated, deskew turned off");
  print_check("elevation check", elevation_check, "corrected / uncorrected", "no offset",
              "the beams are where the scans say, the elevation correction turned off");
  const auto& rings = summary["rings"];
  if (rings["source"] == "learned")
    std::printf("rings from the scans' own %d beams (%+.2f .. %+.2f deg): %s\n", rings["beams"].get<int>(),
                rings["highest_deg"].get<double>(), rings["lowest_deg"].get<double>(),
                rings["reason"].get<std::string>().c_str());
  if (rings.contains("cropped_fraction") && rings["cropped_fraction"].get<double>() > 0.1)
    std::printf("note: the ring table leaves out %d of the scans' %d beams (%.0f %% of the returns); "
                "rings.lidar: auto would use them\n",
                rings["cropped_beams"].get<int>(), rings["scan_beams"].get<int>(),
                100 * rings["cropped_fraction"].get<double>());
  for (const auto& [stage, t] : summary["timing_ms"].items()) {
    if (t["count"].get<std::size_t>() == 0) {
      std::printf("  %-18s (none)\n", stage.c_str());
      continue;
    }
    std::printf("  %-18s median %7.2f ms  mean %7.2f ms  p95 %7.2f ms  (%zu)\n", stage.c_str(),
                t["median"].get<double>(), t["mean"].get<double>(), t["p95"].get<double>(),
                t["count"].get<std::size_t>());
  }
  if (summary.contains("loops")) {
    const auto& l = summary["loops"];
    std::printf("loops: %zu candidates, %zu accepted, %zu rejected\n",
                l["candidates"].get<std::size_t>(), l["accepted"].get<std::size_t>(),
                l["rejected"].get<std::size_t>());
  }
  auto accuracy_line = [](const char* name, const nlohmann::json& a) {
    if (!a["t_err_pct"].is_number()) {
      std::printf("%-10s t_err n/a (path shorter than 100 m)  ATE %.3f m\n", name,
                  a["ate_rmse_m"].get<double>());
      return;
    }
    // The horizontal / vertical parts (eval's split; absent when the ground truth spans no plane).
    char split[96] = "";
    if (a.contains("t_err_vertical_pct") && a["t_err_vertical_pct"].is_number())
      std::snprintf(split, sizeof split, " (horizontal %.3f, vertical %.3f)",
                    a["t_err_horizontal_pct"].get<double>(), a["t_err_vertical_pct"].get<double>());
    std::printf("%-10s t_err %.3f %%%s  r_err %.4f deg/100m  ATE %.3f m  (KITTI metric vs ground truth)\n",
                name, a["t_err_pct"].get<double>(), split, a["r_err_deg_per_100m"].get<double>(),
                a["ate_rmse_m"].get<double>());
  };
  if (summary.contains("odometry_accuracy")) accuracy_line("odometry", summary["odometry_accuracy"]);
  if (summary.contains("accuracy")) accuracy_line(summary["mode"].get<std::string>().c_str(), summary["accuracy"]);
}

// config/ beside the sources: $SCFLOAM_CONFIG_DIR, else <binary>/../../config (build*/bin/scfloam).
std::filesystem::path preset_path(const std::string& sensor) {
  if (sensor == "livox")
    throw Error("--sensor livox: not supported. The feature extraction works on scan rings (a ring field, "
                "or rings from the elevation of a multi-beam fan) and takes curvature along each ring; a "
                "Livox non-repetitive pattern has neither (docs/inputs.md)");
  const char* names[][2] = {{"kitti", "kitti-hdl64"}, {"hdl64", "hdl64"}, {"hdl32", "hdl32"},
                            {"vlp16", "vlp16"}, {"os1-64", "os1-64"}, {"os1-128", "os1-128"},
                            {"auto", "auto"}};
  std::string file;
  for (const auto& n : names)
    if (sensor == n[0]) file = std::string(n[1]) + ".yaml";
  if (file.empty())
    throw Error("--sensor: unknown sensor '" + sensor + "' (kitti, hdl64, hdl32, vlp16, os1-64, os1-128, auto, livox)");
  std::vector<std::filesystem::path> dirs;
  if (const char* env = std::getenv("SCFLOAM_CONFIG_DIR")) dirs.emplace_back(env);
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) dirs.push_back(exe.parent_path().parent_path().parent_path() / "config");
  for (const auto& d : dirs)
    if (std::filesystem::exists(d / file)) return d / file;
  std::string looked;
  for (const auto& d : dirs) looked += " " + (d / file).string();
  throw Error("--sensor " + sensor + ": preset not found (looked at" + looked + "; set SCFLOAM_CONFIG_DIR)");
}

void overlay(YAML::Node base, const YAML::Node& top) {
  for (const auto& kv : top) {
    const std::string key = kv.first.as<std::string>();
    if (kv.second.IsMap() && base[key] && base[key].IsMap()) overlay(base[key], kv.second);
    else base[key] = kv.second;
  }
}

// Whether a YAML document sets the key at this path (maps all the way down).
bool yaml_has(YAML::Node node, std::initializer_list<const char*> path) {
  for (const char* key : path) {
    if (!node.IsMap() || !node[key]) return false;
    node.reset(node[key]);  // rebinds (operator= would write into the document)
  }
  return true;
}

// `sensor` (given or guessed) picks a preset; --config on top of it overrides the keys it sets.
// "kitti" is the built-in defaults and needs no file.
SlamConfig load_run_config(const RunArgs& args, const std::string& sensor) {
  if (sensor == "kitti" && args.sensor.empty())
    return args.config_file.empty() ? SlamConfig{} : load_config(args.config_file);
  const SlamConfig preset = load_config(preset_path(sensor));
  if (args.config_file.empty()) return preset;
  load_config(args.config_file);  // its own errors name the user's file
  YAML::Node merged = YAML::Load(config_to_yaml(preset));
  overlay(merged, YAML::LoadFile(args.config_file));
  const auto tmp = std::filesystem::temp_directory_path() / ("scfloam-config-" + std::to_string(::getpid()) + ".yaml");
  {
    std::ofstream out(tmp);
    out << YAML::Dump(merged) << "\n";
  }
  const SlamConfig config = load_config(tmp);
  std::filesystem::remove(tmp);
  return config;
}

void run(const RunArgs& args) {
  const auto mode = parse_mode(args.mode);
  if (!mode) throw Error("--mode: unknown mode '" + args.mode + "' (odometry, simple-sc, optimized)");
  const auto frame = parse_pose_frame(args.frame);
  if (!frame) throw Error("--frame: unknown frame '" + args.frame + "' (lidar, camera, auto)");
  if (!args.sensor.empty()) preset_path(args.sensor);  // an unknown --sensor fails before any input is read
  ScanSourceOptions source_options;
  source_options.topic = args.topic;
  source_options.timestamps_file = args.timestamps;
  const auto source = open_scan_source(args.input, source_options);
  // Without --sensor the scans' beams choose the preset: KITTI's settings (0.22 deg of beam
  // correction, its leaf sizes, no deskew) on a VLP-16 cost 19x in drift (docs/inputs.md).
  SensorGuess guess;
  if (args.sensor.empty()) {
    guess = guess_sensor(*source);
    if (!args.quiet)
      std::fprintf(stderr, "sensor: %s, from the scans (%s); --sensor chooses another\n", guess.preset.c_str(),
                   guess.reason.c_str());
  }
  const std::string sensor = args.sensor.empty() ? guess.preset : args.sensor;
  SlamConfig config = load_run_config(args, sensor);
  // Per-point times mean a raw driver's, motion-distorted scans, which the presets of raw
  // sensors deskew; a guessed HDL-64E (KITTI's preset: its scans are compensated) is deskewed
  // too, unless --config says otherwise: on a motion-distorted HDL-64E world that is 0.70 %
  // drift against 0.063 % (docs/inputs.md).
  const bool per_point_times = source->size() > 0 && source->load(0).has_time;
  const bool config_sets_deskew = !args.config_file.empty() && yaml_has(YAML::LoadFile(args.config_file),
                                                                         {"odometry", "preprocess", "deskew"});
  if (args.sensor.empty() && per_point_times && !config.odometry.preprocess.deskew && !config_sets_deskew) {
    config.odometry.preprocess.deskew = true;
    guess.reason += "; deskew on: the scans carry per-point times";
    if (!args.quiet)
      std::fprintf(stderr, "sensor: deskew on, the scans carry per-point times (checked in the first frames: "
                           "compensated scans continue without it)\n");
  }
  OutputOptions outputs;
  outputs.map_voxel_m = args.map_voxel_m;
  outputs.write_ply = args.ply;
  outputs.save_keyframes = args.save_keyframes;
  outputs.frame = *frame;
  outputs.map_min_range_m = config.odometry.preprocess.min_range_m;
  outputs.map_max_range_m = config.odometry.preprocess.max_range_m;
  check_output_options(*source, outputs);
  std::filesystem::path out_dir = args.out_dir;
  if (out_dir.empty())
    out_dir = std::filesystem::path("scfloam_out") /
              std::filesystem::weakly_canonical(args.input).filename();
  prepare_output_dir(out_dir, args.force);
  if (!args.quiet) std::fprintf(stderr, "input: %s\n", source->describe().c_str());
  const bool kitti_input = detect_input_kind(args.input) == InputKind::kKitti;
  if (kitti_input && config.odometry.rings.lidar == "hdl64" && config.odometry.preprocess.elevation_correction_deg == 0)
    std::fprintf(stderr,
                 "note: an HDL-64E without elevation correction on a KITTI sequence: KITTI's own scans read "
                 "~0.22 deg low (a steady pitch drift); --sensor kitti corrects that\n");
  if (!config.odometry.preprocess.deskew && per_point_times)
    std::fprintf(stderr,
                 "note: the scans carry per-point times but deskew is off (KITTI's preset: its scans are "
                 "motion-compensated); for raw scans pass --sensor for your sensor, or set "
                 "odometry.preprocess.deskew: true\n");

  RunOptions options;
  options.mode = *mode;
  options.max_frames = args.frames;
  options.progress = !args.quiet;
  options.deterministic = args.deterministic;
  options.stop = &install_interrupt_handlers();
  const RunResult result = run_slam(*source, config, options);
  nlohmann::json summary = make_summary(*source, result);
  summary["sensor"] = {{"preset", sensor},
                       {"from", args.sensor.empty() ? "scans" : "--sensor"},
                       {"deskew", config.odometry.preprocess.deskew}};
  if (args.sensor.empty()) summary["sensor"]["reason"] = guess.reason;
  summary["interrupted"] = result.interrupted;
  write_run_outputs(out_dir, *source, result, summary, outputs);
  print_report(summary);
  std::printf("results in %s\n", out_dir.string().c_str());
  if (result.interrupted) {
    // The results of the frames processed are complete; the exit code says they are not all.
    std::printf("interrupted after %zu of %zu frames\n", result.T_world_lidar.size(),
                args.frames ? std::min(args.frames, source->size()) : source->size());
    std::fflush(stdout);
    std::exit(128 + interrupt_signal());
  }
}

RegisterCommand reg("run", [](CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  auto* sub = app.add_subcommand("run", "Run SLAM on a recorded sequence (default mode: optimized, the paper's method)");
  sub->add_option("input", args->input,
                  "Input: KITTI directory, folder of .pcd/.ply/.bin scans, scan file, or ROS bag (see `scfloam info`)")
      ->required();
  sub->add_option("-o,--out", args->out_dir, "Output folder (default: scfloam_out/<input name>)");
  sub->add_option("-m,--mode", args->mode, "odometry | simple-sc | optimized");
  sub->add_option("-c,--config", args->config_file, "YAML configuration (see config/)");
  sub->add_option("-n,--frames", args->frames, "Process only the first N scans");
  sub->add_option("-s,--sensor", args->sensor,
                  "Sensor preset: kitti (the defaults: KITTI's HDL-64E scans) | hdl64 | hdl32 | vlp16 | os1-64 | "
                  "os1-128 | auto (another spinning sensor: beams learned from the scans) (config/); --config "
                  "overrides its keys. Default: chosen from the scans' beams (kitti for an HDL-64E)");
  sub->add_option("--topic", args->topic, "Bags: the PointCloud2 topic (auto when there is only one)");
  sub->add_option("--timestamps", args->timestamps, "Folders: file with one stamp (s) per scan, in scan order");
  sub->add_option("--frame", args->frame, "KITTI trajectories in lidar | camera | auto (camera when the input has Tr)");
  sub->add_option("--map-voxel", args->map_voxel_m, "Voxel size of map.pcd/map.ply in metres (default 0.2)");
  sub->add_flag("--ply", args->ply, "Also write map.ply (binary little endian, x y z intensity)");
  sub->add_flag("--save-keyframes", args->save_keyframes,
                "Write keyframes/NNNNNN.pcd (lidar frame) and keyframes/poses_kitti.txt to rebuild maps");
  sub->add_flag("-f,--force", args->force, "Overwrite an existing result in the output folder");
  sub->add_flag("-q,--quiet", args->quiet, "No progress bar");
  sub->add_flag("--deterministic", args->deterministic,
                "Loop work in frame order on one thread: identical output for identical input");
  sub->callback([args] { run(*args); });
});

}  // namespace
}  // namespace scfloam::cli
