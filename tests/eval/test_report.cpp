// The report: every JSON field present and parseable, table text, and the SVG figure.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "scfloam/error.hpp"
#include "scfloam/eval/eval_plots.hpp"
#include "scfloam/eval/report.hpp"
#include "scfloam/eval/svg_plot.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {
namespace {

PoseList loop_path(std::size_t frames) {
  PoseList poses;
  for (std::size_t i = 0; i < frames; ++i) {
    const double a = 2 * M_PI * static_cast<double>(i) / static_cast<double>(frames);
    Pose T = Pose::Identity();
    T.linear() = so3_exp(Eigen::Vector3d(0, -a, 0));
    T.translation() = Eigen::Vector3d(100 * std::sin(a), 0, 100 * (1 - std::cos(a)));
    poses.push_back(T);
  }
  return poses;
}

PoseList scaled(const PoseList& in, double s) {
  PoseList out = in;
  for (auto& T : out) T.translation() *= s;
  return out;
}

TEST(EvalReport, JsonHasEveryField) {
  const PoseList gt = loop_path(700);
  EvalReport r = evaluate_trajectory(gt, scaled(gt, 1.01));
  r.gt_name = "gt.txt";
  r.est_name = "est.txt";
  const std::string line = eval_json(r);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  const auto j = nlohmann::json::parse(line);
  for (const char* key : {"frames", "t_err_pct", "r_err_deg_per_100m", "kitti_segments",
                          "path_length_m", "per_length", "ate_rmse_m", "ate_mean_m",
                          "ate_median_m", "ate_max_m", "rpe_pairs", "rpe_trans_rmse_m",
                          "rpe_trans_mean_m", "rpe_rot_rmse_deg", "rpe_rot_mean_deg", "note",
                          "gt", "est", "association", "gt_poses", "est_poses",
                          "t_err_horizontal_pct", "t_err_vertical_pct"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["frames"].get<int>(), 700);
  EXPECT_NEAR(j["t_err_pct"].get<double>(), r.kitti.t_err_pct, 1e-12);
  EXPECT_GT(j["t_err_pct"].get<double>(), 0.5);
  EXPECT_NEAR(j["ate_rmse_m"].get<double>(), r.ate.rmse_m, 1e-12);
  ASSERT_EQ(j["per_length"].size(), 8u);
  EXPECT_EQ(j["per_length"][0]["length_m"].get<double>(), 100.0);
  for (const char* key : {"segments", "t_err_pct", "r_err_deg_per_100m"})
    EXPECT_TRUE(j["per_length"][7].contains(key)) << key;
  EXPECT_EQ(j["gt"], "gt.txt");

  const std::string table = format_eval_table(r);
  EXPECT_NE(table.find("t_err"), std::string::npos);
  EXPECT_NE(table.find("ATE"), std::string::npos);
  EXPECT_NE(table.find("     800"), std::string::npos);
  // A scale error of a level loop is all horizontal.
  EXPECT_NEAR(j["t_err_horizontal_pct"].get<double>(), r.kitti.t_err_pct, 1e-9);
  EXPECT_NEAR(j["t_err_vertical_pct"].get<double>(), 0.0, 1e-9);
  EXPECT_NE(table.find("horizontal"), std::string::npos);
}

TEST(EvalReport, ShortPathGivesNullNotZero) {
  PoseList gt;
  for (int i = 0; i < 50; ++i) {
    Pose T = Pose::Identity();
    T.translation().z() = i;
    gt.push_back(T);
  }
  const EvalReport r = evaluate_trajectory(gt, gt);
  const auto j = nlohmann::json::parse(eval_json(r));
  EXPECT_TRUE(j["t_err_pct"].is_null());
  EXPECT_TRUE(j["r_err_deg_per_100m"].is_null());
  EXPECT_TRUE(j["per_length"][0]["t_err_pct"].is_null());
  EXPECT_TRUE(j["t_err_vertical_pct"].is_null());
  EXPECT_EQ(j["kitti_segments"].get<int>(), 0);
  EXPECT_NE(j["note"].get<std::string>().find("shorter than"), std::string::npos);
  EXPECT_NE(format_eval_table(r).find("n/a"), std::string::npos);
}

TEST(SvgPlot, NiceTicksAreRoundAndCover) {
  const auto t = svg::nice_ticks(0.0, 800.0, 5);
  ASSERT_GE(t.size(), 4u);
  EXPECT_DOUBLE_EQ(t.front(), 0.0);
  EXPECT_DOUBLE_EQ(t.back(), 800.0);
  const auto u = svg::nice_ticks(-3.2, 7.9, 6);
  EXPECT_DOUBLE_EQ(u[1] - u[0], 2.0);
  EXPECT_GE(u.front(), -3.2);
  EXPECT_LE(u.back(), 7.9);
  EXPECT_EQ(svg::escape("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
}

TEST(EvalPlot, SvgHasPanelsLegendAndLoops) {
  const PoseList gt = loop_path(600);
  const PoseList est = scaled(gt, 1.02);
  const EvalReport r = evaluate_trajectory(gt, est);
  EvalPlotInput in;
  in.report = &r;
  in.gt = &gt;
  in.est = &est;
  in.loops = {{590, 5}, {595, 2}};
  in.heading = "est vs gt";
  const std::string svg = eval_plot_svg(in);
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  for (const char* text : {"Top view", "raw (as in the file)", "x [m]", "z [m]", "segment length [m]",
                           "t_err [%]", "r_err [deg/100 m]", "error [m]", "ground truth",
                           "accepted loops (2)"})
    EXPECT_NE(svg.find(text), std::string::npos) << text;
  // Two loop links drawn in loop red.
  std::size_t links = 0;
  for (auto p = svg.find("stroke=\"#d62728\""); p != std::string::npos;
       p = svg.find("stroke=\"#d62728\"", p + 1))
    ++links;
  EXPECT_EQ(links, 3u);  // 2 links + the legend sample

  in.loops = {{600, 0}};
  EXPECT_THROW(eval_plot_svg(in), Error);
}

}  // namespace
}  // namespace scfloam
