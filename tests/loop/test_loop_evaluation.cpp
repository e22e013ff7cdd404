#include <gtest/gtest.h>

#include "loop/synthetic_scene.hpp"
#include "scfloam/error.hpp"
#include "scfloam/loop/loop_evaluation.hpp"

namespace scfloam {
namespace {

// Keyframes every 2 m:  0..149 east along y = 0; 150..199 far north; 200..219 east along
// y = 0 again (same direction, revisits 0..19); 220..239 far north; 240..259 west along
// y = 1 (opposite direction, revisits 100..81); 260..264 north across y = 0 at x = 150
// (a crossing of keyframe 75).
PoseList hand_made_route() {
  PoseList poses;
  for (int i = 0; i < 150; ++i) poses.push_back(test::pose_xy_yaw(2.0 * i, 0, 0));
  for (int i = 0; i < 50; ++i) poses.push_back(test::pose_xy_yaw(2.0 * i, 1000, 0));
  for (int i = 0; i < 20; ++i) poses.push_back(test::pose_xy_yaw(2.0 * i, 0, 0));
  for (int i = 0; i < 20; ++i) poses.push_back(test::pose_xy_yaw(2.0 * i, 2000, 0));
  for (int i = 0; i < 20; ++i) poses.push_back(test::pose_xy_yaw(200.0 - 2.0 * i, 1, M_PI));
  for (int i = 0; i < 5; ++i) poses.push_back(test::pose_xy_yaw(150, -4.0 + 2.0 * i, M_PI / 2));
  return poses;
}

LoopCandidate accepted(int current_kf, int loop_kf) {
  LoopCandidate c;
  c.current_kf = current_kf;
  c.loop_kf = loop_kf;
  c.verdict = LoopVerdict::kAccepted;
  return c;
}

TEST(LoopEvaluation, FindsEpisodesByDirection) {
  const auto episodes = find_revisit_episodes(hand_made_route(), LoopEvaluationConfig{});
  ASSERT_EQ(episodes.size(), 3u);
  EXPECT_EQ(episodes[0].first_kf, 200);
  EXPECT_EQ(episodes[0].last_kf, 219);
  EXPECT_EQ(episodes[0].direction, RevisitDirection::kSame);
  EXPECT_EQ(episodes[1].first_kf, 240);
  EXPECT_EQ(episodes[1].last_kf, 259);
  EXPECT_EQ(episodes[1].direction, RevisitDirection::kOpposite);
  // The crossing is within 5 m of keyframe 75 for y in [-4, 4]: keyframes 260..264.
  EXPECT_EQ(episodes[2].first_kf, 260);
  EXPECT_EQ(episodes[2].last_kf, 264);
  EXPECT_EQ(episodes[2].direction, RevisitDirection::kCrossing);
}

TEST(LoopEvaluation, PrecisionAndRecallOfAHandMadeCase) {
  const PoseList gt = hand_made_route();
  std::vector<LoopCandidate> candidates = {
      accepted(205, 5),    // same-direction revisit, 0 m: true
      accepted(250, 90),   // opposite, (180, 1) vs (180, 0): true
      accepted(230, 10),   // far north vs y = 0: false
      accepted(251, 94),   // (178, 1) vs (188, 0): 10 m, false at the 5 m tolerance
  };
  LoopCandidate gated = accepted(262, 75);
  gated.verdict = LoopVerdict::kRejectedGate;  // not a detection: ignored
  candidates.push_back(gated);

  const LoopEvaluation e = evaluate_loops(gt, candidates, LoopEvaluationConfig{});
  EXPECT_EQ(e.accepted, 4);
  EXPECT_EQ(e.true_positives, 2);
  EXPECT_DOUBLE_EQ(e.precision(), 0.5);
  ASSERT_EQ(e.false_positives.size(), 2u);
  EXPECT_EQ(e.false_positives[0].current_kf, 230);
  EXPECT_EQ(e.same.episodes, 1);
  EXPECT_EQ(e.same.found, 1);
  EXPECT_EQ(e.opposite.episodes, 1);
  EXPECT_EQ(e.opposite.found, 1);
  EXPECT_EQ(e.crossing.episodes, 1);
  EXPECT_EQ(e.crossing.found, 0);
  EXPECT_DOUBLE_EQ(e.crossing.recall(), 0.0);

  // Only the false detection left: no episode is found, precision 0.
  const LoopEvaluation bad = evaluate_loops(gt, {accepted(230, 10)}, LoopEvaluationConfig{});
  EXPECT_DOUBLE_EQ(bad.precision(), 0.0);
  EXPECT_DOUBLE_EQ(bad.same.recall(), 0.0);
  EXPECT_DOUBLE_EQ(bad.opposite.recall(), 0.0);
  // Nothing accepted: precision is vacuously 1.
  EXPECT_DOUBLE_EQ(evaluate_loops(gt, {}, LoopEvaluationConfig{}).precision(), 1.0);
}

TEST(LoopEvaluation, GapAndRadiusAreRespected) {
  LoopEvaluationConfig config;
  config.min_keyframe_gap = 250;  // nothing on the route is that far apart and close in space
  EXPECT_TRUE(find_revisit_episodes(hand_made_route(), config).empty());
  config = LoopEvaluationConfig{};
  config.correct_radius_m = 11.0;
  EXPECT_EQ(evaluate_loops(hand_made_route(), {accepted(251, 94)}, config).true_positives, 1);
  EXPECT_THROW(evaluate_loops(hand_made_route(), {accepted(900, 1)}, config), Error);
}

}  // namespace
}  // namespace scfloam
