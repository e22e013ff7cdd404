// `scfloam run INPUT`: the whole system on a recorded sequence.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "command_registry.hpp"
#include "interrupt.hpp"
#include "scfloam/error.hpp"
#include "scfloam/pipeline/outputs.hpp"
#include "scfloam/pipeline/pipeline.hpp"

namespace scfloam::cli {
namespace {

struct RunArgs {
  std::string input;
  std::string out_dir;
  std::string mode = "optimized";
  std::string config_file;
  std::size_t frames = 0;
  bool force = false;
  bool quiet = false;
  bool deterministic = false;
};

void print_report(const nlohmann::json& summary) {
  std::printf("frames %zu, keyframes %zu, %.1f s wall, %.1f frames/s, peak memory %.0f MB\n",
              summary["frames"].get<std::size_t>(), summary["keyframes"].get<std::size_t>(),
              summary["wall_s"].get<double>(), summary["fps"].get<double>(),
              summary["peak_rss_mb"].get<double>());
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
    std::printf("%-10s t_err %.3f %%  r_err %.4f deg/100m  ATE %.3f m  (KITTI metric vs ground truth)\n",
                name, a["t_err_pct"].get<double>(), a["r_err_deg_per_100m"].get<double>(),
                a["ate_rmse_m"].get<double>());
  };
  if (summary.contains("odometry_accuracy")) accuracy_line("odometry", summary["odometry_accuracy"]);
  if (summary.contains("accuracy")) accuracy_line(summary["mode"].get<std::string>().c_str(), summary["accuracy"]);
}

void run(const RunArgs& args) {
  const auto mode = parse_mode(args.mode);
  if (!mode) throw Error("--mode: unknown mode '" + args.mode + "' (odometry, simple-sc, optimized)");
  const SlamConfig config = args.config_file.empty() ? SlamConfig{} : load_config(args.config_file);
  const auto source = open_scan_source(args.input);
  std::filesystem::path out_dir = args.out_dir;
  if (out_dir.empty())
    out_dir = std::filesystem::path("scfloam_out") /
              std::filesystem::weakly_canonical(args.input).filename();
  prepare_output_dir(out_dir, args.force);
  if (!args.quiet) std::fprintf(stderr, "input: %s\n", source->describe().c_str());

  RunOptions options;
  options.mode = *mode;
  options.max_frames = args.frames;
  options.progress = !args.quiet;
  options.deterministic = args.deterministic;
  options.stop = &install_interrupt_handlers();
  const RunResult result = run_slam(*source, config, options);
  nlohmann::json summary = make_summary(*source, result);
  summary["interrupted"] = result.interrupted;
  write_run_outputs(out_dir, *source, result, summary);
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
  sub->add_option("input", args->input, "Input sequence (KITTI odometry directory)")->required();
  sub->add_option("-o,--out", args->out_dir, "Output folder (default: scfloam_out/<input name>)");
  sub->add_option("-m,--mode", args->mode, "odometry | simple-sc | optimized");
  sub->add_option("-c,--config", args->config_file, "YAML configuration (see config/)");
  sub->add_option("-n,--frames", args->frames, "Process only the first N scans");
  sub->add_flag("-f,--force", args->force, "Overwrite an existing result in the output folder");
  sub->add_flag("-q,--quiet", args->quiet, "No progress bar");
  sub->add_flag("--deterministic", args->deterministic,
                "Loop work in frame order on one thread: identical output for identical input");
  sub->callback([args] { run(*args); });
});

}  // namespace
}  // namespace scfloam::cli
