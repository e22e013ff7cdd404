// `scfloam eval --gt GT --est EST`: KITTI devkit metric, ATE and RPE of an estimated trajectory,
// printed as a table followed by one JSON line (the last line of output), plus an SVG figure.
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include "command_registry.hpp"
#include "scfloam/eval/eval_plots.hpp"
#include "scfloam/eval/report.hpp"
#include "scfloam/eval/trajectory_input.hpp"

namespace {

struct EvalOptions {
  std::string gt, est, format = "auto", gt_format, est_format, gt_times, est_times, plot, loops;
  double max_dt_s = 0.02;
  bool plot_aligned = false;
};

std::optional<std::filesystem::path> optional_path(const std::string& s) {
  if (s.empty()) return std::nullopt;
  return std::filesystem::path(s);
}

void run_eval(const EvalOptions& o) {
  using namespace scfloam;
  const auto fmt_of = [&](const std::string& specific) {
    return parse_trajectory_format(specific.empty() ? o.format : specific);
  };
  const LoadedTrajectory gt = load_trajectory(o.gt, fmt_of(o.gt_format), optional_path(o.gt_times));
  const LoadedTrajectory est = load_trajectory(o.est, fmt_of(o.est_format), optional_path(o.est_times));
  const AssociatedTrajectories pairs = associate_trajectories(gt, est, o.max_dt_s);

  EvalReport report = evaluate_trajectory(pairs.gt, pairs.est);
  report.gt_name = o.gt;
  report.est_name = o.est;
  report.association = pairs.method;
  report.gt_total = pairs.gt_total;
  report.est_total = pairs.est_total;
  std::cout << format_eval_table(report);

  if (!o.plot.empty()) {
    EvalPlotInput plot;
    plot.report = &report;
    plot.gt = &pairs.gt;
    plot.est = &pairs.est;
    plot.draw_aligned = o.plot_aligned;
    plot.heading = std::filesystem::path(o.est).filename().string() + " vs " +
                   std::filesystem::path(o.gt).filename().string();
    if (!o.loops.empty()) {
      const auto loops = read_accepted_loops(o.loops);
      plot.loops = loops_to_pairs(loops, pairs.est_index);
      std::cout << "loops: " << loops.size() << " accepted in " << o.loops << ", "
                << plot.loops.size() << " drawn (both frames evaluated)\n";
    }
    write_eval_plot_svg(o.plot, plot);
    std::cout << "plot: " << o.plot << "\n";
  }
  std::cout << eval_json(report) << std::endl;
}

scfloam::cli::RegisterCommand reg("eval", [](CLI::App& app) {
  auto opts = std::make_shared<EvalOptions>();
  auto* sub = app.add_subcommand(
      "eval",
      "Accuracy of an estimated trajectory: KITTI t_err/r_err, ATE, RPE; table then one JSON line");
  sub->add_option("--gt", opts->gt, "Ground-truth trajectory (KITTI camera-0 poses or TUM)")
      ->required()->check(CLI::ExistingFile);
  sub->add_option("--est", opts->est, "Estimated trajectory (same convention as --gt)")
      ->required()->check(CLI::ExistingFile);
  sub->add_option("--format", opts->format, "Format of both files: auto (12 numbers a line = KITTI, 8 = TUM), kitti, tum")
      ->capture_default_str()->check(CLI::IsMember({"auto", "kitti", "tum"}));
  sub->add_option("--gt-format", opts->gt_format, "Format of --gt only (overrides --format)")
      ->check(CLI::IsMember({"auto", "kitti", "tum"}));
  sub->add_option("--est-format", opts->est_format, "Format of --est only (overrides --format)")
      ->check(CLI::IsMember({"auto", "kitti", "tum"}));
  sub->add_option("--gt-times", opts->gt_times, "times.txt giving timestamps to a KITTI --gt (pairs it with a TUM --est)")
      ->check(CLI::ExistingFile);
  sub->add_option("--est-times", opts->est_times, "times.txt giving timestamps to a KITTI --est")
      ->check(CLI::ExistingFile);
  sub->add_option("--max-dt", opts->max_dt_s, "Timestamp association tolerance [s]")
      ->capture_default_str()->check(CLI::PositiveNumber);
  auto* plot = sub->add_option("--plot", opts->plot, "Write the figure (top view, error vs length, per-frame error) to this SVG file");
  sub->add_flag("--plot-aligned", opts->plot_aligned, "Top view shows the estimate after SE(3) alignment instead of raw")
      ->needs(plot);
  sub->add_option("--loops", opts->loops, "loops.csv: draw its accepted loops as links in the top view")
      ->check(CLI::ExistingFile)->needs(plot);
  sub->callback([opts] { run_eval(*opts); });
});

}  // namespace
