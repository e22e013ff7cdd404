// A revisit after a concentrated odometry heading failure: does the graph close the loop?
#include <gtest/gtest.h>

#include <cmath>

#include "scfloam/backend/pose_graph.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {
namespace {

Eigen::Isometry3d step(double forward_m, double yaw_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3_exp(Eigen::Vector3d(0, 0, yaw_rad));
  T.translation() = Eigen::Vector3d(forward_m, 0, 0);
  return T;
}

class PoseGraphLargeLoop : public ::testing::TestWithParam<std::size_t> {};

TEST_P(PoseGraphLargeLoop, ClosesALoopAfterAHeadingFailure) {
  const std::size_t loops = GetParam();
  // A 400 x 200 m rectangle driven once (2 m per keyframe), back to the start; the odometry
  // over-turns by 20 degrees in ten keyframes of the second corner.
  PoseGraphConfig config;
  PoseGraph graph;
  std::vector<Eigen::Isometry3d> truth{Eigen::Isometry3d::Identity()};
  Eigen::Isometry3d odo = Eigen::Isometry3d::Identity();
  graph.add_node(odo);
  const int side_a = 200, side_b = 100;
  int k = 0;
  for (int side = 0; side < 4; ++side) {
    const int n = side % 2 == 0 ? side_a : side_b;
    for (int i = 0; i < n; ++i, ++k) {
      const bool corner = i == n - 1;
      const Eigen::Isometry3d true_step = step(2.0, corner ? M_PI / 2 : 0.0);
      Eigen::Isometry3d measured = true_step;
      if (side == 1 && i >= n - 10) measured = step(2.0, (corner ? M_PI / 2 : 0.0) + 2.0 * M_PI / 180);
      truth.push_back(truth.back() * true_step);
      odo = odo * measured;
      graph.add_node(odo);
      graph.add_odometry_edge(k, k + 1, measured, config);
    }
  }
  const std::size_t last = truth.size() - 1;
  ASSERT_GT((odo.translation() - truth[last].translation()).norm(), 50.0);
  // True loops between the last keyframes and the first ones (40-80 m apart).
  for (std::size_t j = 1; j <= loops; ++j) {
    const std::size_t cur = last - 20 + j, old = j;
    graph.add_loop_edge(cur, old, truth[cur].inverse() * truth[old], config);
  }
  // Default configuration: least squares, chi-square switch-off, Cauchy polish.
  graph.optimize(config);
  double worst_m = 0;
  for (std::size_t j = 1; j <= loops; ++j) {
    const std::size_t cur = last - 20 + j;
    const Eigen::Isometry3d estimated = graph.pose(cur).inverse() * graph.pose(j);
    const Eigen::Isometry3d expected = truth[cur].inverse() * truth[j];
    worst_m = std::max(worst_m, (estimated.translation() - expected.translation()).norm());
  }
  EXPECT_LT(worst_m, 0.5);
}

INSTANTIATE_TEST_SUITE_P(OneOrTwentyLoops, PoseGraphLargeLoop, ::testing::Values(1u, 20u));

}  // namespace
}  // namespace scfloam
