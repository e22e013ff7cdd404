#include <gtest/gtest.h>

#include <vector>

#include "loop/synthetic_scene.hpp"
#include "scfloam/error.hpp"
#include "scfloam/loop/keyframe_selector.hpp"

namespace scfloam {
namespace {

std::vector<int> keyframes_of(const std::vector<Eigen::Isometry3d>& poses) {
  KeyframeSelector selector(2.0, 10.0 * M_PI / 180.0);
  std::vector<int> keyframes;
  for (int i = 0; i < static_cast<int>(poses.size()); ++i)
    if (selector.update(poses[i])) keyframes.push_back(i);
  return keyframes;
}

TEST(KeyframeSelector, EveryTwoMetresOfTravel) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 13; ++i) poses.push_back(test::pose_xy_yaw(0.6 * i, 0, 0.3));
  // 0.6 m per frame: 2.4 m reached at frames 4, 8, 12.
  EXPECT_EQ(keyframes_of(poses), (std::vector<int>{0, 4, 8, 12}));
}

TEST(KeyframeSelector, EveryTenDegreesOfRotationInPlace) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 9; ++i) poses.push_back(test::pose_xy_yaw(5, 5, 3.0 * i * M_PI / 180.0));
  // 3 degrees per frame: 12 degrees reached at frames 4 and 8.
  EXPECT_EQ(keyframes_of(poses), (std::vector<int>{0, 4, 8}));
}

TEST(KeyframeSelector, RotationAccumulatesEvenWhenTurningBack) {
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i < 6; ++i) poses.push_back(test::pose_xy_yaw(0, 0, (i % 2) * 4.0 * M_PI / 180.0));
  // +-4 degrees each frame: 12 accumulated at frame 3; the net rotation never exceeds 4.
  EXPECT_EQ(keyframes_of(poses), (std::vector<int>{0, 3}));
}

TEST(KeyframeSelector, StandingStillGivesOnlyTheFirstKeyframe) {
  const std::vector<Eigen::Isometry3d> poses(20, test::pose_xy_yaw(1, 2, 0.5));
  EXPECT_EQ(keyframes_of(poses), (std::vector<int>{0}));
}

TEST(KeyframeSelector, RejectsNonPositiveThresholds) {
  EXPECT_THROW(KeyframeSelector(0.0, 0.1), Error);
  EXPECT_THROW(KeyframeSelector(2.0, -1.0), Error);
}

}  // namespace
}  // namespace scfloam
