// The loop edge's information from the match (loop_edge_information): a perturbation of the
// registration's solution must cost the same in the registration's own information and in the
// pose-graph edge's, i.e. the information is carried through the right Jacobian.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <random>

#include "scfloam/loop/loop_registration.hpp"
#include "scfloam/se3.hpp"

using namespace scfloam;

namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

Eigen::Isometry3d pose(double rx, double ry, double rz, double x, double y, double z) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3_exp(Eigen::Vector3d(rx, ry, rz));
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

// The registration's perturbation: R' = Exp(w) R, t' = t + v, delta = [w; v].
Eigen::Isometry3d perturb(const Eigen::Isometry3d& T, const Vector6& delta) {
  Eigen::Isometry3d out = T;
  out.linear() = so3_exp(delta.head<3>()) * T.linear();
  out.translation() = T.translation() + delta.tail<3>();
  return out;
}

// The pose graph's loop edge residual [Log R_E; t_E], E = Z^-1 T_current_loop, for the edge
// current -> loop with measurement Z (src/backend/pose_graph_costs.hpp).
Vector6 edge_residual(const Eigen::Isometry3d& Z, const Eigen::Isometry3d& T_current_loop) {
  const Eigen::Isometry3d E = Z.inverse() * T_current_loop;
  Vector6 r;
  r << so3_log(E.linear()), E.translation();
  return r;
}

RegistrationResult registration_with(const Eigen::Isometry3d& T_anchor_current, std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  Eigen::Matrix<double, 6, 6> A;
  for (int i = 0; i < 36; ++i) A.data()[i] = n(rng);
  RegistrationResult r;
  r.T_world_lidar = T_anchor_current;
  r.hessian = A * A.transpose() * 1e4 + Matrix6::Identity() * 100;  // anisotropic, SPD
  r.residual_variance_m2 = 4e-4;
  return r;
}

}  // namespace

TEST(LoopEdgeInformation, CostOfAPerturbationIsTheSameInBothFrames) {
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0, 1);
  for (int trial = 0; trial < 20; ++trial) {
    // Anchor and loop keyframe apart (a submap anchored on a neighbour), current far from both.
    const Eigen::Isometry3d T_anchor_loop = pose(0.02 * n(rng), 0.03 * n(rng), 0.5 * n(rng),
                                                 8 * n(rng), 8 * n(rng), 0.5 * n(rng));
    const Eigen::Isometry3d T_anchor_current = pose(0.02 * n(rng), 0.03 * n(rng), 2 * n(rng),
                                                    20 * n(rng), 20 * n(rng), n(rng));
    const RegistrationResult r = registration_with(T_anchor_current, rng);
    const double inflation = 3.0;
    const Matrix6 info = loop_edge_information(r, T_anchor_loop, inflation);
    ASSERT_FALSE(info.isZero());
    const Matrix6 reg_info = r.hessian / (r.residual_variance_m2 * inflation);

    // The edge's measurement from the solution, and the true relative pose it estimates.
    const Eigen::Isometry3d T_current_loop = T_anchor_current.inverse() * T_anchor_loop;
    for (int k = 0; k < 6; ++k) {
      Vector6 delta;
      for (int i = 0; i < 6; ++i) delta[i] = n(rng);
      delta *= 1e-6;
      // The match found T_anchor_current perturbed by delta: its measurement Z' is off by delta.
      const Eigen::Isometry3d Z = (T_anchor_loop.inverse() * perturb(T_anchor_current, delta)).inverse();
      const Vector6 e = edge_residual(Z, T_current_loop);
      const double cost_edge = e.dot(info * e);
      const double cost_registration = delta.dot(reg_info * delta);
      EXPECT_NEAR(cost_edge / cost_registration, 1.0, 1e-3) << "trial " << trial << " k " << k;
    }
  }
}

TEST(LoopEdgeInformation, ScalesWithTheResidualVarianceAndTheInflation) {
  std::mt19937 rng(7);
  const Eigen::Isometry3d T_anchor_loop = pose(0, 0, 0.3, 2, -1, 0);
  RegistrationResult r = registration_with(pose(0.01, 0, 1.0, 10, 5, 0.2), rng);
  const Matrix6 base = loop_edge_information(r, T_anchor_loop, 1.0);
  EXPECT_TRUE(base.isApprox(base.transpose()));
  EXPECT_EQ(base.llt().info(), Eigen::Success);  // positive definite
  EXPECT_TRUE(loop_edge_information(r, T_anchor_loop, 4.0).isApprox(base / 4.0));
  r.residual_variance_m2 *= 2;
  EXPECT_TRUE(loop_edge_information(r, T_anchor_loop, 1.0).isApprox(base / 2.0));
}

TEST(LoopEdgeInformation, NoInformationFromAnUnusableMatch) {
  std::mt19937 rng(9);
  const Eigen::Isometry3d T_anchor_loop = pose(0, 0, 0.3, 2, -1, 0);
  RegistrationResult r = registration_with(pose(0, 0, 1.0, 10, 5, 0), rng);
  EXPECT_TRUE(loop_edge_information(r, T_anchor_loop, 0.0).isZero());  // switched off
  RegistrationResult no_variance = r;
  no_variance.residual_variance_m2 = 0;  // too few matches for a variance
  EXPECT_TRUE(loop_edge_information(no_variance, T_anchor_loop, 1.0).isZero());
  RegistrationResult degenerate = r;
  degenerate.hessian.row(5).setZero();  // a direction the match does not constrain
  degenerate.hessian.col(5).setZero();
  EXPECT_TRUE(loop_edge_information(degenerate, T_anchor_loop, 1.0).isZero());
}
