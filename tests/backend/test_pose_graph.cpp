#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include "scfloam/backend/pose_graph.hpp"
#include "scfloam/se3.hpp"
#include "test_paths.hpp"

using namespace scfloam;

namespace {

Eigen::Isometry3d make_pose(double yaw, double x, double y, double z = 0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3_exp(Eigen::Vector3d(0, 0, yaw));
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

// A square drive of 4 x 25 m in 1 m steps, ending where it started.
PoseList square_truth() {
  PoseList truth;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int side = 0; side < 4; ++side) {
    for (int step = 0; step < 25; ++step) {
      truth.push_back(T);
      T = T * make_pose(step == 24 ? M_PI / 2 : 0.0, 1.0, 0.0);
    }
  }
  truth.push_back(T);  // back at the start (node 100 ~ node 0)
  return truth;
}

double max_position_error(const PoseList& a, const PoseList& b) {
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    worst = std::max(worst, (a[i].translation() - b[i].translation()).norm());
  return worst;
}

// Odometry with a small yaw bias per step: the square does not close.
PoseList drifted(const PoseList& truth, double yaw_bias_per_step) {
  PoseList out{truth[0]};
  for (std::size_t i = 1; i < truth.size(); ++i)
    out.push_back(out.back() * (truth[i - 1].inverse() * truth[i]) *
                  make_pose(yaw_bias_per_step, 0, 0));
  return out;
}

// Nodes at the odometry's poses, chained by its relative motions.
PoseGraph odometry_chain(const PoseList& odom, const PoseGraphConfig& config) {
  PoseGraph graph;
  for (const auto& T : odom) graph.add_node(T);
  for (std::size_t i = 1; i < odom.size(); ++i)
    graph.add_odometry_edge(i - 1, i, odom[i - 1].inverse() * odom[i], config);
  return graph;
}

}  // namespace

TEST(PoseGraph, ClosesASquareLoopWithDrift) {
  const PoseList truth = square_truth();
  // 1.7 deg per 100 m: worse than any usable odometry, well inside its 1e-3 rad sigma per edge.
  const PoseList odom = drifted(truth, 3e-4);
  ASSERT_GT(max_position_error(truth, odom), 0.4);  // the drift is real

  PoseGraphConfig config;
  PoseGraph graph = odometry_chain(odom, config);
  // The loop: the last node is measured to coincide with the first.
  graph.add_loop_edge(odom.size() - 1, 0, truth.back().inverse() * truth[0], config);
  const PoseGraphReport report = graph.optimize(config);
  EXPECT_LT(report.final_cost, report.initial_cost);
  const PoseList fixed = graph.poses();
  EXPECT_TRUE(report.rejected_edges.empty());
  EXPECT_LT(max_position_error(truth, fixed), 0.3);
  EXPECT_LT((fixed.back().translation() - fixed.front().translation()).norm(), 0.1);
  EXPECT_TRUE(fixed[0].isApprox(odom[0], 1e-12));  // node 0 is the fixed origin
}

// A bounded window: nodes before it are not moved, edges among them are left out. A loop
// inside the window gets the whole-graph answer, since the older nodes cannot help it.
TEST(PoseGraph, BoundedWindowHoldsTheOlderNodesAndMatchesTheWholeGraph) {
  const PoseList truth = square_truth();
  const PoseList odom = drifted(truth, 3e-4);
  const std::size_t first = 50, last = odom.size() - 1;
  const Eigen::Isometry3d T_meas = truth[last].inverse() * truth[first];
  PoseGraphConfig config;
  auto make_graph = [&] {
    PoseGraph graph = odometry_chain(odom, config);
    graph.add_loop_edge(last, first, T_meas, config);
    return graph;
  };
  PoseGraph window = make_graph(), whole = make_graph();
  const PoseGraphReport report = window.optimize(config, first);
  EXPECT_FALSE(report.escalated);  // the loop fits within the window: no need to free more
  EXPECT_EQ(report.first_free_node, first);
  whole.optimize(config);
  for (std::size_t i = 0; i < first; ++i) EXPECT_TRUE(window.pose(i).isApprox(odom[i], 1e-12)) << i;
  auto gap_m = [&](const PoseGraph& g) {
    return ((g.pose(last).inverse() * g.pose(first)).translation() - T_meas.translation()).norm();
  };
  const double open_m = ((odom[last].inverse() * odom[first]).translation() - T_meas.translation()).norm();
  EXPECT_LT(gap_m(window), 0.5 * open_m);
  for (std::size_t i = first; i <= last; ++i)
    EXPECT_LT((window.pose(i).translation() - whole.pose(i).translation()).norm(), 1e-3) << i;
}

// A window too short to absorb a loop's discrepancy must not judge the loop: anchored nodes
// carry drift only the whole graph can remove. The solve escalates to the whole graph, which
// keeps a true loop and still switches off a false one.
TEST(PoseGraph, WindowTooShortForALoopEscalatesToTheWholeGraph) {
  const PoseList truth = square_truth();
  const PoseList odom = drifted(truth, 3e-4);
  const std::size_t last = odom.size() - 1, first_free = last - 5;
  PoseGraphConfig config;
  auto make_graph = [&](bool with_false_loop) {
    PoseGraph graph = odometry_chain(odom, config);
    graph.add_loop_edge(last, 0, truth[last].inverse() * truth[0], config);
    if (with_false_loop)  // claims node 97 sits on node 60: metres wrong
      graph.add_loop_edge(last - 3, 60, Eigen::Isometry3d::Identity(), config);
    return graph;
  };
  // Held to its last 5 nodes, the loop cannot fit: the window alone would call it an outlier.
  {
    PoseGraph held = make_graph(false);
    PoseGraphConfig no_judging = config;
    no_judging.loop_outlier_chi2 = std::numeric_limits<double>::infinity();
    EXPECT_FALSE(held.optimize(no_judging, first_free).escalated);
    EXPECT_GT(held.edge_chi2(held.edges().size() - 1), config.loop_outlier_chi2);
  }
  PoseGraph graph = make_graph(false);
  const PoseGraphReport report = graph.optimize(config, first_free);
  EXPECT_TRUE(report.escalated);
  EXPECT_EQ(report.first_free_node, 0u);
  EXPECT_TRUE(report.rejected_edges.empty());
  EXPECT_EQ(graph.loop_edge_count(), 1u);
  EXPECT_LT(max_position_error(truth, graph.poses()), 0.3);  // closed as by a whole solve

  PoseGraph polluted = make_graph(true);
  const PoseGraphReport polluted_report = polluted.optimize(config, first_free);
  EXPECT_TRUE(polluted_report.escalated);
  ASSERT_EQ(polluted_report.rejected_edges.size(), 1u);
  EXPECT_EQ(polluted.edges()[polluted_report.rejected_edges[0]].to, 60u);
  EXPECT_EQ(polluted.loop_edge_count(), 1u);
  EXPECT_LT(max_position_error(truth, polluted.poses()), 0.3);
}

// A loop switched off by an earlier solve (say, while a false loop pulled the graph its way)
// is given back once it fits the solution without it; a loop that still misfits stays off.
TEST(PoseGraph, SwitchesBackOnAnEarlierRejectedLoopThatFitsAgain) {
  const PoseList truth = square_truth();
  const PoseList odom = drifted(truth, 3e-4);
  PoseGraphConfig config;
  PoseGraph graph = odometry_chain(odom, config);
  const Eigen::Matrix<double, 6, 6> info =
      sqrt_information_from_sigmas(config.loop_rotation_sigma_rad, config.loop_translation_sigma_m);
  const std::size_t last = odom.size() - 1;
  graph.add_edge({last, 0, truth[last].inverse() * truth[0], info, true, true});
  // Switched off earlier: a true loop (node 99 on node 1) and a false one (node 75 on node 25).
  graph.add_edge({last - 1, 1, truth[last - 1].inverse() * truth[1], info, true, false});
  graph.add_edge({75, 25, Eigen::Isometry3d::Identity(), info, true, false});
  const PoseGraphReport report = graph.optimize(config);
  EXPECT_TRUE(report.rejected_edges.empty());
  ASSERT_EQ(report.restored_edges.size(), 1u);
  EXPECT_EQ(graph.edges()[report.restored_edges[0]].from, last - 1);
  EXPECT_TRUE(graph.edges()[report.restored_edges[0]].active);
  EXPECT_FALSE(graph.edges().back().active);
  EXPECT_EQ(graph.loop_edge_count(), 2u);
  EXPECT_LT(graph.edge_chi2(report.restored_edges[0]), config.loop_outlier_chi2);
  EXPECT_LT(max_position_error(truth, graph.poses()), 0.3);
}

TEST(PoseGraph, RobustKernelLimitsAFalseLoop) {
  const PoseList truth = square_truth();
  PoseGraphConfig config;
  auto solve = [&](bool with_false_loop) {
    PoseGraph graph;
    for (const auto& T : truth) graph.add_node(T);
    for (std::size_t i = 1; i < truth.size(); ++i)
      graph.add_odometry_edge(i - 1, i, truth[i - 1].inverse() * truth[i], config);
    graph.add_loop_edge(truth.size() - 1, 0, Eigen::Isometry3d::Identity(), config);
    if (with_false_loop)  // claims node 50 sits on node 10: 30 m wrong
      graph.add_loop_edge(50, 10, Eigen::Isometry3d::Identity(), config);
    const PoseGraphReport report = graph.optimize(config);
    // The false loop, and only it, is found inconsistent and switched off.
    if (with_false_loop) {
      EXPECT_EQ(report.rejected_edges.size(), 1u);
      if (!report.rejected_edges.empty()) {
        EXPECT_EQ(graph.edges()[report.rejected_edges[0]].from, 50u);
      }
    } else {
      EXPECT_TRUE(report.rejected_edges.empty());
    }
    return graph.poses();
  };
  const PoseList clean = solve(false);
  const PoseList polluted = solve(true);
  EXPECT_LT(max_position_error(truth, clean), 1e-3);
  // Without the kernel the false edge would pull the square together by metres.
  EXPECT_LT(max_position_error(truth, polluted), 1e-3);
}

TEST(PoseGraph, RejectsEdgesToMissingNodes) {
  PoseGraph graph;
  graph.add_node(Eigen::Isometry3d::Identity());
  EXPECT_THROW(graph.add_odometry_edge(0, 3, Eigen::Isometry3d::Identity(), {}), std::exception);
}

TEST(PoseGraph, G2oFileListsVerticesAndEdges) {
  PoseGraph graph;
  PoseGraphConfig config;
  graph.add_node(Eigen::Isometry3d::Identity());
  graph.add_node(make_pose(0.1, 2, 0));
  graph.add_odometry_edge(0, 1, make_pose(0.1, 2, 0), config);
  const auto dir = test::scratch_dir("pose_graph_g2o");
  graph.write_g2o(dir / "graph.g2o");
  std::ifstream in(dir / "graph.g2o");
  std::string line;
  int vertices = 0, edges = 0;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "VERTEX_SE3:QUAT") ++vertices;
    if (tag == "EDGE_SE3:QUAT") {
      ++edges;
      std::vector<double> v;
      double x;
      while (s >> x) v.push_back(x);
      ASSERT_EQ(v.size(), 2u + 7u + 21u);
      // Translation information first in g2o: 1 / sigma_t^2.
      EXPECT_NEAR(v[9], 1.0 / (config.odometry_translation_sigma_m * config.odometry_translation_sigma_m), 1e-3);
      EXPECT_NEAR(v[2], 2.0, 1e-9);
    }
  }
  EXPECT_EQ(vertices, 2);
  EXPECT_EQ(edges, 1);
}

#include "backend/pose_graph_costs.hpp"

TEST(PoseGraph, AnalyticJacobiansMatchNumericDifferentiation) {
  using namespace pose_graph_detail;
  const Eigen::Isometry3d Z = make_pose(0.3, 1.0, -2.0, 0.5);
  Eigen::Matrix<double, 6, 6> sqrt_info = Eigen::Matrix<double, 6, 6>::Identity();
  sqrt_info.diagonal() << 10, 20, 30, 1, 2, 3;
  const RelativePoseCost cost(Z, sqrt_info);
  const PoseManifold manifold;
  auto node = [](const Eigen::Isometry3d& T) {
    const Eigen::Quaterniond q(T.linear());
    return std::array<double, 7>{T.translation().x(), T.translation().y(), T.translation().z(),
                                 q.x(), q.y(), q.z(), q.w()};
  };
  Eigen::Isometry3d Ta = make_pose(0.2, 3, 1, 0.2);
  Ta.linear() = Ta.linear() * so3_exp(Eigen::Vector3d(0.05, -0.1, 0.0));
  const Eigen::Isometry3d Tb = Ta * Z * make_pose(0.2, 0.3, -0.1, 0.05);  // not at the optimum
  std::array<double, 7> a = node(Ta), b = node(Tb);
  const double* params[2] = {a.data(), b.data()};
  Eigen::Matrix<double, 6, 1> r0;
  Eigen::Matrix<double, 6, 7, Eigen::RowMajor> Ja, Jb;
  double* jac[2] = {Ja.data(), Jb.data()};
  ASSERT_TRUE(cost.Evaluate(params, r0.data(), jac));
  Eigen::Matrix<double, 7, 6, Eigen::RowMajor> lift;
  manifold.PlusJacobian(a.data(), lift.data());
  const Eigen::Matrix<double, 6, 6> Ja_tangent = Ja * lift, Jb_tangent = Jb * lift;
  for (int which = 0; which < 2; ++which) {
    for (int k = 0; k < 6; ++k) {
      const double h = 1e-6;
      double delta[6] = {0, 0, 0, 0, 0, 0};
      delta[k] = h;
      std::array<double, 7> plus = which == 0 ? a : b, minus = plus;
      manifold.Plus((which == 0 ? a : b).data(), delta, plus.data());
      delta[k] = -h;
      manifold.Plus((which == 0 ? a : b).data(), delta, minus.data());
      Eigen::Matrix<double, 6, 1> rp, rm;
      const double* pp[2] = {which == 0 ? plus.data() : a.data(), which == 1 ? plus.data() : b.data()};
      const double* pm[2] = {which == 0 ? minus.data() : a.data(), which == 1 ? minus.data() : b.data()};
      cost.Evaluate(pp, rp.data(), nullptr);
      cost.Evaluate(pm, rm.data(), nullptr);
      const Eigen::Matrix<double, 6, 1> numeric = (rp - rm) / (2 * h);
      const Eigen::Matrix<double, 6, 1> analytic = (which == 0 ? Ja_tangent : Jb_tangent).col(k);
      EXPECT_LT((numeric - analytic).norm(), 1e-5 * (1 + numeric.norm()))
          << "node " << which << " tangent " << k << "\nnumeric " << numeric.transpose()
          << "\nanalytic " << analytic.transpose();
    }
  }
}

