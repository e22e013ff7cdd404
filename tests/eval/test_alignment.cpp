// Umeyama SE(3) alignment, ATE and RPE on known transforms and perturbations.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scfloam/error.hpp"
#include "scfloam/eval/alignment.hpp"
#include "scfloam/eval/rpe.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {
namespace {

PoseList wiggly_path(std::size_t frames) {
  PoseList poses;
  for (std::size_t i = 0; i < frames; ++i) {
    const double s = static_cast<double>(i);
    Pose T = Pose::Identity();
    T.linear() = so3_exp(Eigen::Vector3d(0.01 * std::sin(0.1 * s), 0.05 * s, 0.0));
    T.translation() = Eigen::Vector3d(10 * std::sin(0.05 * s), 0.5 * std::cos(0.2 * s), s);
    poses.push_back(T);
  }
  return poses;
}

Pose known_transform() {
  Pose T = Pose::Identity();
  T.linear() = so3_exp(Eigen::Vector3d(0.3, -1.1, 0.7));
  T.translation() = Eigen::Vector3d(12.5, -3.0, 40.0);
  return T;
}

TEST(Umeyama, RecoversAKnownTransform) {
  const PoseList gt = wiggly_path(200);
  const Pose T_est_gt = known_transform();
  PoseList est;
  for (const auto& T : gt) est.push_back(T_est_gt * T);
  const AteResult ate = absolute_trajectory_error(gt, est);
  // The alignment maps est into gt, i.e. the inverse of the transform applied.
  EXPECT_TRUE(ate.T_gt_est.isApprox(T_est_gt.inverse(), 1e-9));
  EXPECT_LT(ate.rmse_m, 1e-9);
  EXPECT_LT(ate.max_m, 1e-9);
  EXPECT_LT(ate_rmse_m(gt, est), 1e-9);
  for (std::size_t i = 0; i < gt.size(); ++i)
    EXPECT_TRUE(ate.aligned_est[i].isApprox(gt[i], 1e-9)) << i;
}

TEST(Ate, MeasuresAKnownOffsetThatAlignmentCannotRemove) {
  // Alternating +/- 0.3 m sideways offsets: zero mean, so the best rigid fit leaves them all.
  const PoseList gt = wiggly_path(100);
  PoseList est = gt;
  for (std::size_t i = 0; i < est.size(); ++i)
    est[i].translation().y() += (i % 2 == 0 ? 0.3 : -0.3);
  const AteResult ate = absolute_trajectory_error(gt, est);
  EXPECT_NEAR(ate.rmse_m, 0.3, 0.01);
  EXPECT_NEAR(ate.median_m, 0.3, 0.01);
  EXPECT_NEAR(ate.mean_m, 0.3, 0.01);
}

TEST(Ate, FewPointsAlignTranslationOnly) {
  PoseList gt(2, Pose::Identity()), est(2, Pose::Identity());
  gt[1].translation() = Eigen::Vector3d(1, 0, 0);
  est[0].translation() = Eigen::Vector3d(5, 5, 5);
  est[1].translation() = Eigen::Vector3d(6, 5, 5);
  EXPECT_NEAR(ate_rmse_m(gt, est), 0.0, 1e-12);
  EXPECT_THROW(absolute_trajectory_error(gt, PoseList(3, Pose::Identity())), Error);
}

TEST(Rpe, ZeroForAnyRigidlyMovedCopyAndKnownForAPerturbedStep) {
  const PoseList gt = wiggly_path(50);
  PoseList moved;
  for (const auto& T : gt) moved.push_back(known_transform() * T);
  const RpeResult same = relative_pose_error(gt, moved);
  EXPECT_EQ(same.pairs(), 49u);
  EXPECT_LT(same.trans_rmse_m, 1e-9);
  EXPECT_LT(same.rot_rmse_deg, 1e-7);

  // The estimate's motion from frame 9 to 10 has an extra 0.2 m forward and 1 deg of yaw in
  // the local frame; every later pose carries it rigidly, so only that one pair is wrong.
  PoseList est = gt;
  Pose extra = Pose::Identity();
  extra.linear() = so3_exp(Eigen::Vector3d(0, M_PI / 180.0, 0));
  extra.translation() = Eigen::Vector3d(0, 0, 0.2);
  for (std::size_t i = 10; i < est.size(); ++i)
    est[i] = gt[9] * extra * gt[9].inverse() * gt[i];
  const RpeResult r = relative_pose_error(gt, est);
  for (std::size_t k = 0; k < r.pairs(); ++k) {
    if (k == 9) {
      EXPECT_NEAR(r.rot_deg[k], 1.0, 1e-9);
      EXPECT_GT(r.trans_m[k], 0.19);
    } else {
      EXPECT_NEAR(r.trans_m[k], 0.0, 1e-9) << k;
      EXPECT_NEAR(r.rot_deg[k], 0.0, 1e-6) << k;
    }
  }
  EXPECT_NEAR(r.rot_mean_deg, 1.0 / 49.0, 1e-6);
  EXPECT_NEAR(r.rot_rmse_deg, std::sqrt(1.0 / 49.0), 1e-6);
}

}  // namespace
}  // namespace scfloam
