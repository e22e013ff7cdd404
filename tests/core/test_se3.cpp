#include <gtest/gtest.h>

#include <random>

#include "scfloam/se3.hpp"
#include "scfloam/stats.hpp"

using namespace scfloam;

TEST(So3, ExpLogRoundTrip) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    Eigen::Vector3d w(u(rng), u(rng), u(rng));
    w *= (i % 3 == 0 ? 1e-7 : 3.0);  // tiny and large angles
    if (w.norm() >= M_PI) w *= 3.0 / w.norm();
    const Eigen::Vector3d back = so3_log(so3_exp(w));
    EXPECT_LT((back - w).norm(), 1e-9) << w.transpose();
  }
}

TEST(So3, RotationAngleKnownAnswers) {
  EXPECT_NEAR(rotation_angle_rad(Eigen::Matrix3d::Identity()), 0.0, 1e-15);
  EXPECT_NEAR(rotation_angle_rad(so3_exp(Eigen::Vector3d(0, 0, 1e-6))), 1e-6, 1e-15);
  EXPECT_NEAR(rotation_angle_rad(so3_exp(Eigen::Vector3d(0.3, -0.4, 0))), 0.5, 1e-12);
  EXPECT_NEAR(rotation_angle_rad(so3_exp(Eigen::Vector3d(0, M_PI - 1e-9, 0))), M_PI, 1e-8);
}

TEST(Se3, OrthonormalizedRepairsDriftedRotation) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3_exp(Eigen::Vector3d(0.1, 0.2, 0.3));
  T.linear() *= 1.001;  // off SO(3)
  T.linear()(0, 1) += 1e-3;
  const Eigen::Isometry3d fixed = orthonormalized(T);
  EXPECT_LT((fixed.linear().transpose() * fixed.linear() - Eigen::Matrix3d::Identity()).norm(),
            1e-12);
  EXPECT_NEAR(fixed.linear().determinant(), 1.0, 1e-12);
}

TEST(Se3, InterpolateEndpointsAndMidpoint) {
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d b = Eigen::Isometry3d::Identity();
  b.linear() = so3_exp(Eigen::Vector3d(0, 0, 0.4));
  b.translation() = Eigen::Vector3d(2, 4, 0);
  EXPECT_TRUE(interpolate(a, b, 0).isApprox(a, 1e-12));
  EXPECT_TRUE(interpolate(a, b, 1).isApprox(b, 1e-12));
  const Eigen::Isometry3d mid = interpolate(a, b, 0.5);
  EXPECT_NEAR(rotation_angle_rad(mid.linear()), 0.2, 1e-12);
  EXPECT_TRUE(mid.translation().isApprox(Eigen::Vector3d(1, 2, 0)));
}

TEST(Stats, MedianMeanP95) {
  std::vector<double> v;
  for (int i = 1; i <= 100; ++i) v.push_back(i);
  const TimingStats s = summarize(v);
  EXPECT_EQ(s.count, 100u);
  EXPECT_DOUBLE_EQ(s.median, 50.5);
  EXPECT_DOUBLE_EQ(s.mean, 50.5);
  EXPECT_DOUBLE_EQ(s.p95, 95);
  EXPECT_EQ(summarize({}).count, 0u);
  EXPECT_DOUBLE_EQ(summarize({7}).p95, 7);
}
