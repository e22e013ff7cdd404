// Analytic Jacobians of the residuals against numerical differentiation through the manifold.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scfloam/registration/feature_costs.hpp"
#include "scfloam/registration/pose_manifold.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {
namespace {

Eigen::Isometry3d some_pose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3_exp(Eigen::Vector3d(0.1, -0.2, 0.7));
  T.translation() = Eigen::Vector3d(120.0, -35.0, 4.0);  // far from the origin on purpose
  return T;
}

// d r / d delta by central differences of r(Plus(x, delta)).
template <typename F>
Eigen::MatrixXd numeric_jacobian(const F& residual, const Eigen::Isometry3d& T, int rows) {
  PoseManifold manifold;
  double x[7], xp[7], xm[7];
  pose_to_block(T, x);
  Eigen::MatrixXd J(rows, 6);
  const double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    double d[6] = {0, 0, 0, 0, 0, 0};
    d[k] = h;
    manifold.Plus(x, d, xp);
    d[k] = -h;
    manifold.Plus(x, d, xm);
    J.col(k) = (residual(block_to_pose(xp)) - residual(block_to_pose(xm))) / (2 * h);
  }
  return J;
}

TEST(FeatureCosts, EdgeResidualIsPointToLineDistanceAndJacobianMatchesNumeric) {
  const Eigen::Isometry3d T = some_pose();
  EdgeMatch m{{3.0, -1.0, 0.5}, T * Eigen::Vector3d(3.5, -1.2, 0.1), Eigen::Vector3d(0.2, 0.9, 0.4).normalized()};
  Jacobian36 J;
  const Eigen::Vector3d r = edge_residual(m, T.linear(), T.translation(), &J);
  const Eigen::Vector3d d = T * m.point_lidar - m.line_point;
  EXPECT_NEAR(r.norm(), d.cross(m.line_dir).norm(), 1e-9);
  EXPECT_NEAR(r.dot(m.line_dir), 0.0, 1e-9);
  const auto f = [&](const Eigen::Isometry3d& X) -> Eigen::VectorXd {
    return edge_residual(m, X.linear(), X.translation(), nullptr);
  };
  EXPECT_LT((numeric_jacobian(f, T, 3) - Eigen::MatrixXd(J)).norm(), 1e-6);
}

TEST(FeatureCosts, PlaneResidualAndJacobianMatchNumeric) {
  const Eigen::Isometry3d T = some_pose();
  const Eigen::Vector3d n = Eigen::Vector3d(0.3, -0.4, 0.87).normalized();
  PlaneMatch m{{-4.0, 2.0, 1.0}, n, -n.dot(T * Eigen::Vector3d(-4.2, 2.1, 0.8))};
  Jacobian16 J;
  const double r = plane_residual(m, T.linear(), T.translation(), &J);
  EXPECT_NEAR(r, n.dot(T * m.point_lidar) + m.offset, 1e-12);
  const auto f = [&](const Eigen::Isometry3d& X) -> Eigen::VectorXd {
    return Eigen::VectorXd::Constant(1, plane_residual(m, X.linear(), X.translation(), nullptr));
  };
  EXPECT_LT((numeric_jacobian(f, T, 1) - Eigen::MatrixXd(J)).norm(), 1e-6);
}

TEST(FeatureCosts, HuberFoldedResidualSquaresToRhoAndJacobianMatchesNumeric) {
  const double delta = 0.1;
  const Eigen::Isometry3d T = some_pose();
  // An outlier edge (residual 0.6 m >> delta) and an inlier.
  for (double offset : {0.6, 0.03}) {
    EdgeMatch m{{3.0, -1.0, 0.5}, T * Eigen::Vector3d(3.0, -1.0 + offset, 0.5), Eigen::Vector3d::UnitZ()};
    Jacobian36 J;
    Eigen::Vector3d r = edge_residual(m, T.linear(), T.translation(), &J);
    const double s = r.squaredNorm();
    robustify_huber<3>(delta, r, &J);
    const double rho = s <= delta * delta ? s : 2 * delta * std::sqrt(s) - delta * delta;
    EXPECT_NEAR(r.squaredNorm(), rho, 1e-12);
    const auto f = [&](const Eigen::Isometry3d& X) -> Eigen::VectorXd {
      Eigen::Vector3d v = edge_residual(m, X.linear(), X.translation(), nullptr);
      robustify_huber<3>(delta, v, nullptr);
      return v;
    };
    EXPECT_LT((numeric_jacobian(f, T, 3) - Eigen::MatrixXd(J)).norm(), 1e-6) << offset;
  }
}

// Evaluates a FeatureCost at pose T: residuals and the row-major 7-column Jacobian.
bool evaluate_at(const FeatureCost& cost, const Eigen::Isometry3d& T, double* residuals, double* jacobian) {
  double x[7];
  pose_to_block(T, x);
  const double* params[] = {x};
  double* jacobians[] = {jacobian};
  return cost.Evaluate(params, residuals, jacobians);
}

// huber_delta_m 0 is documented as "no robust loss": the fold must leave the residual and
// Jacobian as they are (it divided by sqrt(0) before, and every solve failed without a word).
TEST(FeatureCosts, HuberDeltaZeroIsPlainLeastSquares) {
  const Eigen::Isometry3d T = some_pose();
  EdgeMatch m{{3.0, -1.0, 0.5}, T * Eigen::Vector3d(3.0, -0.4, 0.5), Eigen::Vector3d::UnitZ()};
  Jacobian36 J;
  Eigen::Vector3d r = edge_residual(m, T.linear(), T.translation(), &J);
  const Eigen::Vector3d r0 = r;
  const Jacobian36 J0 = J;
  robustify_huber<3>(0.0, r, &J);
  EXPECT_TRUE(r.allFinite());
  EXPECT_EQ(r, r0);
  EXPECT_EQ(J, J0);
  std::vector<EdgeMatch> edges{m};
  std::vector<PlaneMatch> planes{{{-1, 0, 2}, Eigen::Vector3d::UnitZ(), -3.0}};
  FeatureCost cost(edges, planes, 0.0);
  double residuals[3], jac[3 * 7];
  ASSERT_TRUE(evaluate_at(cost, T, residuals, jac));
  EXPECT_NEAR(std::hypot(residuals[0], residuals[1]), r0.norm(), 1e-12);
  for (double v : jac) EXPECT_TRUE(std::isfinite(v));
}

TEST(FeatureCosts, CeresCostEvaluatesEveryMatchWithTangentJacobian) {
  const Eigen::Isometry3d T = some_pose();
  std::vector<EdgeMatch> edges{{{1, 2, 3}, {100, -30, 5}, Eigen::Vector3d::UnitX()}};
  std::vector<PlaneMatch> planes{{{-1, 0, 2}, Eigen::Vector3d::UnitZ(), -3.0}};
  FeatureCost cost(edges, planes, 0.1);
  ASSERT_EQ(cost.num_residuals(), 3);  // two rows per edge, one per plane
  double residuals[3], jac[3 * 7];
  ASSERT_TRUE(evaluate_at(cost, T, residuals, jac));
  // Edge: the two rows carry the robustified point-to-line vector's norm and its J^T J.
  Jacobian36 Je;
  Eigen::Vector3d re = edge_residual(edges[0], T.linear(), T.translation(), &Je);
  robustify_huber<3>(0.1, re, &Je);
  EXPECT_NEAR(std::hypot(residuals[0], residuals[1]), re.norm(), 1e-12);
  Eigen::Matrix<double, 2, 6> J2;
  for (int i = 0; i < 2; ++i)
    for (int k = 0; k < 6; ++k) J2(i, k) = jac[i * 7 + k];
  EXPECT_LT((J2.transpose() * J2 - Je.transpose() * Je).norm(), 1e-9 * (Je.transpose() * Je).norm());
  EXPECT_NEAR(Eigen::Vector2d(residuals[0], residuals[1]).dot(J2.col(3)),
              re.dot(Je.col(3)), 1e-9);  // same gradient
  Jacobian16 Jp;
  Eigen::Matrix<double, 1, 1> rp(plane_residual(planes[0], T.linear(), T.translation(), &Jp));
  robustify_huber<1>(0.1, rp, &Jp);
  EXPECT_NEAR(residuals[2], rp[0], 1e-12);
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(jac[2 * 7 + k], Jp[k], 1e-12);
  EXPECT_EQ(jac[2 * 7 + 6], 0.0);
}

// Random matches, some far enough off for the Huber loss to bend them.
void random_matches(std::vector<EdgeMatch>& edges, std::vector<PlaneMatch>& planes, int n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  auto vec = [&](double s) { return Eigen::Vector3d(s * u(rng), s * u(rng), s * u(rng)); };
  for (int i = 0; i < n; ++i) {
    edges.push_back({vec(30), Eigen::Vector3d(120, -35, 4) + vec(30), vec(1).normalized()});
    planes.push_back({vec(30), vec(1).normalized(), 0.3 * u(rng)});
  }
}

TEST(FeatureCosts, NormalEquationCostHasFeatureCostsCostGradientAndGaussNewtonMatrix) {
  std::vector<EdgeMatch> edges;
  std::vector<PlaneMatch> planes;
  random_matches(edges, planes, 1500);  // > one summation block of each kind
  const FeatureCost full(edges, planes, 0.1);
  tbb::task_arena arena(2);
  for (tbb::task_arena* a : {static_cast<tbb::task_arena*>(nullptr), &arena}) {
    const NormalEquationCost compact(edges, planes, 0.1, a);
    ASSERT_EQ(compact.num_residuals(), 7);
    double x[7];
    pose_to_block(some_pose(), x);
    const double* params[] = {x};
    const int rows = full.num_residuals();
    Eigen::VectorXd r_full(rows);
    Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor> J_full(rows, 7);
    double* jf[] = {J_full.data()};
    ASSERT_TRUE(full.Evaluate(params, r_full.data(), jf));
    Eigen::Matrix<double, 7, 1> r;
    Eigen::Matrix<double, 7, 7, Eigen::RowMajor> J;
    double* jc[] = {J.data()};
    ASSERT_TRUE(compact.Evaluate(params, r.data(), jc));
    const double cost = r_full.squaredNorm();
    EXPECT_NEAR(r.squaredNorm(), cost, 1e-10 * cost);
    const Eigen::MatrixXd H_full = J_full.transpose() * J_full, H = J.transpose() * J;
    EXPECT_LT((H - H_full).norm(), 1e-10 * H_full.norm());
    const Eigen::VectorXd g_full = J_full.transpose() * r_full, g = J.transpose() * r;
    EXPECT_LT((g - g_full).norm(), 1e-10 * g_full.norm());
    // Cost alone (the trial steps): the same value.
    Eigen::Matrix<double, 7, 1> r_only;
    ASSERT_TRUE(compact.Evaluate(params, r_only.data(), nullptr));
    EXPECT_NEAR(r_only.squaredNorm(), cost, 1e-10 * cost);
  }
}

TEST(FeatureCosts, NormalEquationCostOfAFloorAloneIsRankDeficientButExact) {
  // Plane matches on z = 0 only: x, y and yaw are unconstrained (J^T J has rank 3).
  std::vector<EdgeMatch> edges;
  std::vector<PlaneMatch> planes;
  for (int i = 0; i < 50; ++i)
    planes.push_back({Eigen::Vector3d(i % 7 - 3.0, i / 7 - 3.0, -1.7), Eigen::Vector3d::UnitZ(), 0.0});
  const NormalEquationCost compact(edges, planes, 0.1);
  const FeatureCost full(edges, planes, 0.1);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(3, 4, 1.75);
  T.linear() = so3_exp(Eigen::Vector3d(0.01, -0.02, 0.5));
  double x[7];
  pose_to_block(T, x);
  const double* params[] = {x};
  Eigen::VectorXd r_full(50);
  Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor> J_full(50, 7);
  double* jf[] = {J_full.data()};
  ASSERT_TRUE(full.Evaluate(params, r_full.data(), jf));
  Eigen::Matrix<double, 7, 1> r;
  Eigen::Matrix<double, 7, 7, Eigen::RowMajor> J;
  double* jc[] = {J.data()};
  ASSERT_TRUE(compact.Evaluate(params, r.data(), jc));
  EXPECT_TRUE(r.allFinite());
  EXPECT_NEAR(r.squaredNorm(), r_full.squaredNorm(), 1e-12);
  EXPECT_LT((J.transpose() * r - J_full.transpose() * r_full).norm(), 1e-9);
  EXPECT_LT((J.transpose() * J - J_full.transpose() * J_full).norm(), 1e-9);
}

TEST(PoseManifold, PlusMinusRoundTripAndStaysOnSO3) {
  PoseManifold m;
  double x[7], y[7], back[6];
  pose_to_block(some_pose(), x);
  const double d[6] = {0.3, -0.1, 0.2, 1.0, -2.0, 0.5};
  m.Plus(x, d, y);
  EXPECT_NEAR(Eigen::Map<Eigen::Quaterniond>(y).norm(), 1.0, 1e-15);
  m.Minus(y, x, back);
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(back[k], d[k], 1e-12);
}

}  // namespace
}  // namespace scfloam
