#include <gtest/gtest.h>

#include "loop/synthetic_scene.hpp"
#include "scfloam/error.hpp"
#include "scfloam/loop/distance_gate.hpp"

namespace scfloam {
namespace {

TEST(DistanceGate, AdaptiveThresholdIsBasePlusKeyframesOverN) {
  const DistanceGate gate = DistanceGate::adaptive(20.0, 40.0);
  EXPECT_DOUBLE_EQ(gate.threshold_m(0), 20.0);
  EXPECT_DOUBLE_EQ(gate.threshold_m(400), 30.0);
  EXPECT_DOUBLE_EQ(gate.threshold_m(4541), 20.0 + 4541.0 / 40.0);
  // The boundary itself passes (d <= d_thre).
  EXPECT_TRUE(gate.accepts(30.0, 400));
  EXPECT_FALSE(gate.accepts(30.000001, 400));
  EXPECT_TRUE(gate.accepts(30.000001, 401));
}

TEST(DistanceGate, FixedThresholdIgnoresTheKeyframeCount) {
  const DistanceGate gate = DistanceGate::fixed(60.0);
  EXPECT_DOUBLE_EQ(gate.threshold_m(0), 60.0);
  EXPECT_DOUBLE_EQ(gate.threshold_m(100000), 60.0);
  EXPECT_TRUE(gate.accepts(60.0, 5));
  EXPECT_FALSE(gate.accepts(60.5, 5));
}

TEST(DistanceGate, FromConfigPicksTheMode) {
  LoopDetectionConfig config;
  EXPECT_DOUBLE_EQ(DistanceGate::from_config(config).threshold_m(80), 22.0);
  config.gate_keyframes_per_m = 10.0;
  EXPECT_DOUBLE_EQ(DistanceGate::from_config(config).threshold_m(80), 28.0);
  config.adaptive_gate = false;
  config.fixed_gate_m = 60.0;
  EXPECT_DOUBLE_EQ(DistanceGate::from_config(config).threshold_m(80), 60.0);
}

TEST(DistanceGate, DistanceIsTheRelativeTranslationNorm) {
  const Eigen::Isometry3d T_world_loop = test::pose_xy_yaw(10, -5, 1.2);
  const Eigen::Isometry3d T_world_current = test::pose_xy_yaw(13, -1, -2.0);
  EXPECT_NEAR(DistanceGate::distance_m(T_world_loop, T_world_current), 5.0, 1e-12);
  EXPECT_NEAR(DistanceGate::distance_m(T_world_current, T_world_loop), 5.0, 1e-12);
}

TEST(DistanceGate, RejectsBadParameters) {
  EXPECT_THROW(DistanceGate::adaptive(20.0, 0.0), Error);
  EXPECT_THROW(DistanceGate::fixed(-1.0), Error);
}

}  // namespace
}  // namespace scfloam
