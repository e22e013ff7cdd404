#include <gtest/gtest.h>

#include "scfloam/error.hpp"
#include "scfloam/loop/path_gate.hpp"

namespace scfloam {
namespace {

// A chain of `n` keyframes, 2 m apart.
GraphPathLengths chain(std::size_t n) {
  GraphPathLengths paths;
  for (std::size_t i = 0; i < n; ++i) paths.add_keyframe(2.0);
  return paths;
}

TEST(GraphPathLengths, AlongTheChainWithoutLoops) {
  const GraphPathLengths paths = chain(101);
  const std::vector<double> d = paths.from(100, {0, 50, 100});
  EXPECT_DOUBLE_EQ(d[0], 200.0);
  EXPECT_DOUBLE_EQ(d[1], 100.0);
  EXPECT_DOUBLE_EQ(d[2], 0.0);
}

TEST(GraphPathLengths, AcceptedLoopsShortenThePath) {
  GraphPathLengths paths = chain(301);
  paths.add_loop(200, 10);  // keyframe 200 revisited keyframe 10
  // From 300 to 5: 100 keyframes to 200, the loop, 5 keyframes back along the chain.
  const std::vector<double> d = paths.from(300, {5, 15, 150});
  EXPECT_DOUBLE_EQ(d[0], 2.0 * (100 + 5));
  EXPECT_DOUBLE_EQ(d[1], 2.0 * (100 + 5));
  EXPECT_DOUBLE_EQ(d[2], 2.0 * 150);  // the chain is shorter than the way through the loop
  paths.clear_loops();
  EXPECT_DOUBLE_EQ(paths.from(300, {5})[0], 2.0 * 295);
}

TEST(GraphPathLengths, TwoLoopsInSeries) {
  GraphPathLengths paths = chain(1001);
  paths.add_loop(400, 100);
  paths.add_loop(900, 420);
  // 1000 -> 900 (100 kf), -> 420, -> 400 (20 kf), -> 100, -> 90 (10 kf).
  EXPECT_DOUBLE_EQ(paths.from(1000, {90})[0], 2.0 * (100 + 20 + 10));
}

TEST(GraphPathLengths, RejectsUnknownKeyframes) {
  GraphPathLengths paths = chain(10);
  EXPECT_THROW(paths.add_loop(3, 10), Error);
  EXPECT_THROW(paths.from(12, {0}), Error);
}

LoopCandidate candidate(int loop_kf, double score, LoopVerdict verdict) {
  LoopCandidate c;
  c.current_kf = 500;
  c.loop_kf = loop_kf;
  c.sc_score = score;
  c.verdict = verdict;
  return c;
}

TEST(Regate, GateThenRankAmongTheScorePassing) {
  LoopQuery q;
  q.evaluated = {candidate(10, 0.10, LoopVerdict::kAccepted),        // too far for its gate
                 candidate(20, 0.20, LoopVerdict::kRejectedRank),    // within: best left
                 candidate(30, 0.25, LoopVerdict::kRejectedGate),    // within, worse score
                 candidate(40, 0.05, LoopVerdict::kRejectedScore)};  // untouched
  q.best = q.evaluated[0];
  regate(
      q, [](const LoopCandidate& c) { return c.loop_kf == 10 ? 80.0 : 30.0; },
      [](const LoopCandidate&) { return 50.0; });
  EXPECT_EQ(q.evaluated[0].verdict, LoopVerdict::kRejectedGate);
  EXPECT_DOUBLE_EQ(q.evaluated[0].distance_m, 80.0);
  EXPECT_DOUBLE_EQ(q.evaluated[0].gate_m, 50.0);
  EXPECT_EQ(q.evaluated[1].verdict, LoopVerdict::kAccepted);
  EXPECT_EQ(q.evaluated[2].verdict, LoopVerdict::kRejectedRank);
  EXPECT_EQ(q.evaluated[3].verdict, LoopVerdict::kRejectedScore);
  ASSERT_TRUE(q.best.has_value());
  EXPECT_EQ(q.best->loop_kf, 20);

  regate(q, [](const LoopCandidate&) { return 90.0; }, [](const LoopCandidate&) { return 50.0; });
  EXPECT_FALSE(q.best.has_value());
}

TEST(DistanceGate, PathGateDefersTheDetectorsGate) {
  LoopDetectionConfig config;
  config.gate_drift_fraction = 0.05;
  EXPECT_TRUE(DistanceGate::from_config(config).accepts(1e6, 10));
  config.gate_drift_fraction = 0.0;
  EXPECT_FALSE(DistanceGate::from_config(config).accepts(1e6, 10));
}

}  // namespace
}  // namespace scfloam
