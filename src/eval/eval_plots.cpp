#include "scfloam/eval/eval_plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "scfloam/atomic_file.hpp"
#include "scfloam/error.hpp"
#include "scfloam/eval/kitti_metric.hpp"
#include "scfloam/eval/svg_plot.hpp"

namespace scfloam {
namespace {

const svg::Style kGtStyle{"#222222", 2.4, "", 1.0};  // wider: visible under an exact estimate
const svg::Style kEstStyle{"#1f77b4", 1.4, "", 1.0};
const svg::Style kLoopStyle{"#d62728", 1.3, "", 0.8};
const svg::Style kRotStyle{"#ff7f0e", 1.8, "", 1.0};
const svg::Style kStartStyle{"#2ca02c", 1.0, "", 1.0};

// The top view drops the axis along which the ground truth varies least: y for KITTI camera
// poses (y points down), z for lidar/world poses (z up).
struct TopViewAxes {
  int h = 0, v = 2;
};
TopViewAxes top_view_axes(const PoseList& gt) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d hi = -lo;
  for (const auto& T : gt) {
    lo = lo.cwiseMin(T.translation());
    hi = hi.cwiseMax(T.translation());
  }
  int up = 0;
  (hi - lo).minCoeff(&up);
  if (up == 0) return {1, 2};
  if (up == 1) return {0, 2};
  return {0, 1};
}

std::string axis_name(int a) { return a == 0 ? "x" : a == 1 ? "y" : "z"; }

std::string fmt(const char* format, double v) {
  if (!std::isfinite(v)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

void draw_top_view(svg::Canvas& canvas, const EvalPlotInput& in) {
  const PoseList& gt = *in.gt;
  const PoseList& est = in.draw_aligned ? in.report->ate.aligned_est : *in.est;
  const TopViewAxes ax = top_view_axes(gt);
  std::vector<double> gx, gy, ex, ey;
  for (const auto& T : gt) {
    gx.push_back(T.translation()[ax.h]);
    gy.push_back(T.translation()[ax.v]);
  }
  for (const auto& T : est) {
    ex.push_back(T.translation()[ax.h]);
    ey.push_back(T.translation()[ax.v]);
  }
  auto [x_lo, x_hi] = std::minmax_element(gx.begin(), gx.end());
  auto [y_lo, y_hi] = std::minmax_element(gy.begin(), gy.end());
  double x_min = *x_lo, x_max = *x_hi, y_min = *y_lo, y_max = *y_hi;
  for (std::size_t i = 0; i < ex.size(); ++i) {
    x_min = std::min(x_min, ex[i]); x_max = std::max(x_max, ex[i]);
    y_min = std::min(y_min, ey[i]); y_max = std::max(y_max, ey[i]);
  }
  const double pad = 0.05 * std::max({x_max - x_min, y_max - y_min, 1.0});
  svg::Panel p(canvas, 80, 70, 740, 740);
  p.set_range(x_min - pad, x_max + pad, y_min - pad, y_max + pad, /*equal_aspect=*/true);
  p.draw_axes(std::string("Top view, estimate ") +
                  (in.draw_aligned ? "after SE(3) alignment" : "raw (as in the file)"),
              axis_name(ax.h) + " [m]", axis_name(ax.v) + " [m]");
  for (const auto& l : in.loops)
    p.segment(ex[l.current_frame], ey[l.current_frame], ex[l.loop_frame], ey[l.loop_frame], kLoopStyle);
  p.polyline(gx, gy, kGtStyle);
  p.polyline(ex, ey, kEstStyle);
  p.markers({gx.front()}, {gy.front()}, kStartStyle, 5);
  std::vector<svg::Panel::LegendEntry> legend = {{"ground truth", kGtStyle, false},
                                                 {"estimate", kEstStyle, false},
                                                 {"start", kStartStyle, true}};
  if (!in.loops.empty())
    legend.push_back({"accepted loops (" + std::to_string(in.loops.size()) + ")", kLoopStyle, false});
  p.legend(legend);
}

// One metric of the per-length breakdown against segment length.
void draw_length_panel(svg::Canvas& canvas, double top_px, const KittiMetric& m, bool rotation) {
  std::vector<double> lx, ly;
  for (const auto& pl : m.per_length) {
    if (pl.segments == 0) continue;
    lx.push_back(pl.length_m);
    ly.push_back(rotation ? pl.r_err_deg_per_100m : pl.t_err_pct);
  }
  svg::Panel p(canvas, 960, top_px, 500, 190);
  const double y_max = ly.empty() ? 1.0 : *std::max_element(ly.begin(), ly.end());
  p.set_range(50, 850, 0, y_max > 0 ? 1.35 * y_max : 1.0);  // headroom for the legend
  p.draw_axes(rotation ? "Rotation error vs segment length" : "Translation error vs segment length",
              "segment length [m]", rotation ? "r_err [deg/100 m]" : "t_err [%]");
  if (ly.empty()) {
    p.center_text("no segments: path shorter than 100 m");
    return;
  }
  const svg::Style& style = rotation ? kRotStyle : kEstStyle;
  p.polyline(lx, ly, style);
  p.markers(lx, ly, style, 4);
  const double mean = rotation ? m.r_err_deg_per_100m : m.t_err_pct;
  svg::Style mean_style = style;
  mean_style.dash = "6,4";
  mean_style.width_px = 1.2;
  p.segment(50, mean, 850, mean, mean_style);
  p.legend({{rotation ? "r_err per length" : "t_err per length", style, false},
            {"mean over all segments " + fmt(rotation ? "%.3f" : "%.2f", mean), mean_style, false}});
}

void draw_frame_error(svg::Canvas& canvas, double top_px, const EvalPlotInput& in) {
  const std::vector<double> dist = trajectory_distances_m(*in.gt);
  const auto& err = in.report->ate.errors_m;
  svg::Panel p(canvas, 960, top_px, 500, 190);
  const double e_max = *std::max_element(err.begin(), err.end());
  // At least 1 cm tall, so round-off errors of an exact estimate look like the zero they are.
  p.set_range(0, std::max(dist.back(), 1.0), 0, std::max(1.35 * e_max, 0.01));
  p.draw_axes("Per-frame translation error (ATE, aligned)", "distance along ground truth [m]",
              "error [m]");
  p.polyline(dist, err, kEstStyle);
  svg::Style rmse_style = kGtStyle;
  rmse_style.dash = "6,4";
  rmse_style.width_px = 1.2;
  p.segment(0, in.report->ate.rmse_m, dist.back(), in.report->ate.rmse_m, rmse_style);
  p.legend({{"|t_gt - t_est|", kEstStyle, false},
            {"RMSE " + fmt("%.3f m", in.report->ate.rmse_m), rmse_style, false}});
}

}  // namespace

std::string eval_plot_svg(const EvalPlotInput& in) {
  if (!in.report || !in.gt || !in.est || in.gt->empty() || in.gt->size() != in.est->size())
    throw Error("plot: needs the report and the associated ground truth and estimate");
  for (const auto& l : in.loops)
    if (l.current_frame >= in.est->size() || l.loop_frame >= in.est->size())
      throw Error("plot: loop " + std::to_string(l.current_frame) + " -> " +
                  std::to_string(l.loop_frame) + " refers to a frame beyond the " +
                  std::to_string(in.est->size()) + " evaluated ones");
  svg::Canvas canvas(1500, 880);
  const auto& r = *in.report;
  canvas.text(750, 26,
              (in.heading.empty() ? std::string() : in.heading + "  |  ") + "t_err " +
                  fmt("%.3f %%", r.kitti.t_err_pct) + "  |  r_err " +
                  fmt("%.4f deg/100 m", r.kitti.r_err_deg_per_100m) + "  |  ATE " +
                  fmt("%.3f m", r.ate.rmse_m) + "  |  " + std::to_string(r.frames) +
                  (r.gt_total > r.frames ? " of " + std::to_string(r.gt_total) + " frames paired" : " frames"),
              15, "middle", 0, true);
  draw_top_view(canvas, in);
  draw_length_panel(canvas, 70, r.kitti, /*rotation=*/false);
  draw_length_panel(canvas, 345, r.kitti, /*rotation=*/true);
  draw_frame_error(canvas, 620, in);
  return canvas.str();
}

void write_eval_plot_svg(const std::filesystem::path& path, const EvalPlotInput& input) {
  write_file_atomic(path, eval_plot_svg(input));
}

}  // namespace scfloam
