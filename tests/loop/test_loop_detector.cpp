#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "loop/synthetic_scene.hpp"
#include "scfloam/error.hpp"
#include "scfloam/loop/loop_detector.hpp"

namespace scfloam {
namespace {

// A database of `count` distinct places, keyframe i at (100 i, 0), frame index 10 i.
void fill_with_distinct_places(LoopDetector& detector, int count, std::uint32_t first_seed) {
  for (int i = 0; i < count; ++i) {
    const auto T_world_lidar = test::pose_xy_yaw(100.0 * i, 0.0, 0.0);
    const auto world = test::random_place(first_seed + i);
    const auto query = detector.add_keyframe(10 * i, T_world_lidar,
                                             test::view_from(world, test::pose_xy_yaw(0, 0, 0)));
    ASSERT_FALSE(query.best.has_value()) << "distinct place " << i << " matched";
  }
}

TEST(LoopDetector, FindsAnOppositeDirectionRevisitWithItsYaw) {
  LoopDetectionConfig config;
  config.adaptive_gate = false;  // poses here are not a trajectory; gate tested separately
  LoopDetector detector(config);
  fill_with_distinct_places(detector, 60, 100);
  // Place 0 again, seen turned by 180 degrees from 0.5 m beside the first visit.
  const auto world = test::random_place(100);
  const Eigen::Isometry3d T_place_current = test::pose_xy_yaw(0.3, 0.4, M_PI);
  const auto query = detector.add_keyframe(600, test::pose_xy_yaw(0, 0, M_PI),
                                           test::view_from(world, T_place_current));
  ASSERT_TRUE(query.best.has_value());
  EXPECT_EQ(query.best->loop_kf, 0);
  EXPECT_EQ(query.best->current_kf, 60);
  EXPECT_EQ(query.best->loop_frame, 0);
  EXPECT_EQ(query.best->current_frame, 600);
  EXPECT_EQ(query.best->verdict, LoopVerdict::kAccepted);
  EXPECT_LT(std::abs(std::remainder(query.best->yaw_rad - M_PI, 2 * M_PI)), 6.0 * M_PI / 180.0);
  EXPECT_LE(query.best->sc_score, config.score_threshold);
}

TEST(LoopDetector, DistinctPlacesAreNotMatched) {
  LoopDetector detector(LoopDetectionConfig{});
  fill_with_distinct_places(detector, 120, 1000);
  const auto query = detector.add_keyframe(5000, test::pose_xy_yaw(0, 0, 0),
                                           test::random_place(99999));
  EXPECT_FALSE(query.best.has_value());
  // 10 ring-key neighbours for the query and for each of its two lateral variants, merged.
  ASSERT_GE(query.evaluated.size(), 10u);
  ASSERT_LE(query.evaluated.size(), 30u);
  for (const auto& c : query.evaluated) {
    EXPECT_EQ(c.verdict, LoopVerdict::kRejectedScore);
    EXPECT_GT(c.sc_score, detector.config().score_threshold);
  }
  // The log keeps one row saying why nothing was accepted: the best score.
  const auto rows = rows_to_log(query);
  ASSERT_EQ(rows.size(), 1u);
  for (const auto& c : query.evaluated) EXPECT_LE(rows[0].sc_score, c.sc_score);
}

TEST(LoopDetector, RecentKeyframesAreExcluded) {
  LoopDetectionConfig config;
  config.exclude_recent_keyframes = 50;
  LoopDetector detector(config);
  const auto cloud = test::random_place(4);  // the same place over and over
  for (int kf = 0; kf < 56; ++kf) {
    const auto query = detector.add_keyframe(kf, test::pose_xy_yaw(0.1 * kf, 0, 0), cloud);
    // Keyframe kf may only match keyframes older than kf - 50.
    EXPECT_EQ(query.evaluated.size(), static_cast<std::size_t>(std::max(0, std::min(10, kf - 50))))
        << "keyframe " << kf;
    for (const auto& c : query.evaluated) EXPECT_LT(c.loop_kf, kf - 50);
    EXPECT_EQ(query.best.has_value(), kf > 50);
  }
}

TEST(LoopDetector, GateRejectsFarCandidatesAndUsesUpdatedPoses) {
  LoopDetectionConfig config;
  config.exclude_recent_keyframes = 2;
  auto three_keyframes = [&](LoopDetector& detector) {
    for (int kf = 0; kf < 3; ++kf)
      detector.add_keyframe(kf, test::pose_xy_yaw(0, 0, 0), test::random_place(500 + kf));
  };
  // Keyframe 0 revisited, but odometry believes it is 40 m away: gate(4 keyframes) = 20.1 m.
  LoopDetector detector(config);
  three_keyframes(detector);
  auto query = detector.add_keyframe(3, test::pose_xy_yaw(40, 0, 0), test::random_place(500));
  ASSERT_EQ(query.evaluated.size(), 1u);
  EXPECT_EQ(query.evaluated[0].verdict, LoopVerdict::kRejectedGate);
  EXPECT_NEAR(query.evaluated[0].distance_m, 40.0, 1e-9);
  EXPECT_DOUBLE_EQ(query.evaluated[0].gate_m, 20.0 + 4.0 / 40.0);
  EXPECT_FALSE(query.best.has_value());

  // After optimization moves keyframe 0 next to the current one, the same query passes.
  LoopDetector optimized(config);
  three_keyframes(optimized);
  PoseList corrected(3, test::pose_xy_yaw(0, 0, 0));
  corrected[0] = test::pose_xy_yaw(35, 0, 0);
  optimized.update_poses(corrected);
  query = optimized.add_keyframe(3, test::pose_xy_yaw(40, 0, 0), test::random_place(500));
  ASSERT_TRUE(query.best.has_value());
  EXPECT_NEAR(query.best->distance_m, 5.0, 1e-9);
  EXPECT_THROW(optimized.update_poses(PoseList(9)), Error);

  // The baseline's fixed gate lets the 40 m candidate through.
  config.adaptive_gate = false;
  config.fixed_gate_m = 60.0;
  LoopDetector baseline(config);
  three_keyframes(baseline);
  query = baseline.add_keyframe(3, test::pose_xy_yaw(40, 0, 0), test::random_place(500));
  ASSERT_TRUE(query.best.has_value());
  EXPECT_DOUBLE_EQ(query.best->gate_m, 60.0);
}

TEST(LoopDetector, OnlyTheBestPassingCandidateIsAccepted) {
  LoopDetectionConfig config;
  config.exclude_recent_keyframes = 0;
  LoopDetector detector(config);
  const auto world = test::random_place(21);
  detector.add_keyframe(0, test::pose_xy_yaw(0, 0, 0), test::view_from(world, test::pose_xy_yaw(0.6, 0, 0)));
  detector.add_keyframe(1, test::pose_xy_yaw(0, 0, 0), test::view_from(world, test::pose_xy_yaw(0.0, 0, 0)));
  const auto query = detector.add_keyframe(2, test::pose_xy_yaw(0, 0, 0), world);
  ASSERT_EQ(query.evaluated.size(), 2u);
  ASSERT_TRUE(query.best.has_value());
  EXPECT_EQ(query.best->loop_kf, 1);  // the closer viewpoint agrees better
  int accepted = 0, rank = 0;
  for (const auto& c : query.evaluated) {
    accepted += c.verdict == LoopVerdict::kAccepted;
    rank += c.verdict == LoopVerdict::kRejectedRank;
  }
  EXPECT_EQ(accepted, 1);
  EXPECT_EQ(rank, 1);
  EXPECT_EQ(rows_to_log(query).size(), 2u);
}

TEST(LoopDetector, LateralAugmentationFindsARevisitInTheOtherLane) {
  // Place 0 revisited 3.2 m to the side, facing the other way (the opposite lane).
  const auto world = test::random_place(100);
  const auto current = test::view_from(world, test::pose_xy_yaw(0.0, 3.2, M_PI));
  const double plain_score = [&] {
    LoopDetectionConfig config;
    config.lateral_augmentation_m = 0.0;
    config.adaptive_gate = false;
    LoopDetector detector(config);
    fill_with_distinct_places(detector, 60, 100);
    const auto query = detector.add_keyframe(600, test::pose_xy_yaw(0, 0, 0), current);
    for (const auto& c : query.evaluated)
      if (c.loop_kf == 0) return c.sc_score;
    return 1.0;
  }();
  LoopDetectionConfig config;
  config.adaptive_gate = false;
  LoopDetector detector(config);
  fill_with_distinct_places(detector, 60, 100);
  const auto query = detector.add_keyframe(600, test::pose_xy_yaw(0, 0, 0), current);
  ASSERT_TRUE(query.best.has_value());
  EXPECT_EQ(query.best->loop_kf, 0);
  EXPECT_LT(query.best->sc_score, plain_score);
  EXPECT_LT(std::abs(std::remainder(query.best->yaw_rad - M_PI, 2 * M_PI)), 6.0 * M_PI / 180.0);
  std::printf("other lane: score %.3f without, %.3f with lateral augmentation\n", plain_score,
              query.best->sc_score);
}

TEST(LoopDetector, LateralDescriptorsMoveTheGridCentre) {
  LoopDetectionConfig config;
  config.lateral_augmentation_m = 3.0;
  // A point 3 m to the left of the sensor is at the centre of the +3 m variant's grid and
  // 6 m from the centre of the -3 m one (ring 1, 4..8 m).
  const std::vector<Eigen::Vector3f> points = {{0.5f, 3.0f, 1.0f}};
  const auto variants = lateral_descriptors(points, config);
  ASSERT_EQ(variants.size(), 2u);
  EXPECT_FLOAT_EQ(variants[0].bins.row(0).maxCoeff(), 3.0f);
  EXPECT_FLOAT_EQ(variants[1].bins.row(1).maxCoeff(), 3.0f);
  config.lateral_augmentation_m = 0.0;
  EXPECT_TRUE(lateral_descriptors(points, config).empty());
}

}  // namespace
}  // namespace scfloam
