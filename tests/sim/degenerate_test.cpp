// The degenerate scenes' geometry and faults: what each scene promises, checked on the
// scenario itself (no rendering of whole sequences).
#include <gtest/gtest.h>

#include <cmath>

#include "scfloam/error.hpp"
#include "scfloam/se3.hpp"
#include "scfloam/sim/degenerate.hpp"

using namespace scfloam;
using namespace scfloam::sim;

namespace {
double speed_mps(const Scenario& sc, std::size_t k) {
  return (sc.frame_pose(k + 1).translation() - sc.frame_pose(k).translation()).norm() /
         (sc.frame_time(k + 1) - sc.frame_time(k));
}
double yaw_rad(const Pose& T) { return std::atan2(T.linear()(1, 0), T.linear()(0, 0)); }
}  // namespace

TEST(DegenerateScenes, PatrolLapRepeatsExactlyWithASmoothRealisticDrive) {
  const std::size_t lap = patrol_lap_frames(1);
  const Scenario sc = make_degenerate_scenario("patrol", 1, 2 * lap + 2);
  ASSERT_EQ(sc.frames, 2 * lap + 2);
  for (std::size_t k : {std::size_t{0}, std::size_t{1}, lap / 3, lap + 1}) {
    const Pose a = sc.frame_pose(k), b = sc.frame_pose(k + lap);
    EXPECT_LT((a.translation() - b.translation()).norm(), 1e-6) << k;
    // Pitch follows the acceleration, a finite difference (one-sided at frame 0): 1e-4 rad.
    EXPECT_LT((a.linear() - b.linear()).norm(), 1e-4) << k;
  }
  double prev_yaw_rate = 0;
  for (std::size_t k = 1; k + 1 < lap; ++k) {
    const double v = speed_mps(sc, k);
    EXPECT_GT(v, 5.0) << k;
    EXPECT_LT(v, 9.0) << k;
    EXPECT_LT(std::abs(v - speed_mps(sc, k - 1)) / 0.1, 1.0) << k;  // m/s^2
    double dyaw = yaw_rad(sc.frame_pose(k + 1)) - yaw_rad(sc.frame_pose(k));
    dyaw = std::atan2(std::sin(dyaw), std::cos(dyaw));
    const double yaw_rate = dyaw / 0.1;
    if (k > 1) {
      EXPECT_LT(std::abs(yaw_rate - prev_yaw_rate) / 0.1, 0.5) << k;  // rad/s^2: no steps
    }
    EXPECT_LT(v * std::abs(yaw_rate), 3.0) << k;                               // lateral m/s^2
    prev_yaw_rate = yaw_rate;
  }
}

TEST(DegenerateScenes, StationaryCarStandsExactlyStillAndBrakesSmoothly) {
  const Scenario sc = make_degenerate_scenario("stationary", 2, 300);
  ASSERT_GT(sc.degenerate_end_frame, sc.degenerate_first_frame + 100);
  const Pose still = sc.frame_pose(sc.degenerate_first_frame);
  for (std::size_t k = sc.degenerate_first_frame; k < sc.degenerate_end_frame; ++k)
    EXPECT_EQ(sc.frame_pose(k).matrix(), still.matrix()) << k;
  EXPECT_GT(speed_mps(sc, 5), 7.0);
  EXPECT_GT(speed_mps(sc, sc.frames - 3), 7.0);
  for (std::size_t k = 1; k + 2 < sc.frames; ++k)
    EXPECT_LT(std::abs(speed_mps(sc, k) - speed_mps(sc, k - 1)) / 0.1, 2.6) << k;  // <= 8 pi / 10 m/s^2
}

TEST(DegenerateScenes, GapStampsJumpOneSecondWhileTheCarMoves) {
  const Scenario sc = make_degenerate_scenario("gap", 4, 60);
  ASSERT_EQ(sc.frames, 60u);
  const std::size_t g = sc.degenerate_first_frame;
  EXPECT_EQ(g, 30u);
  for (std::size_t k = 1; k < sc.frames; ++k)
    EXPECT_NEAR(sc.frame_time(k) - sc.frame_time(k - 1), k == g ? 1.1 : 0.1, 1e-9) << k;
  const double moved = (sc.frame_pose(g).translation() - sc.frame_pose(g - 1).translation()).norm();
  EXPECT_GT(moved, 5.0 * 1.1);  // the car drives on at >= 5 m/s through the gap
}

TEST(DegenerateScenes, BeamLossesRemoveEveryOtherOrTheUpperRings) {
  Scenario sc;
  sc.beam_losses.push_back({10, 20, 2, 0.0});
  sc.beam_losses.push_back({20, 30, 1, 0.5});
  Scan full;
  for (int ring = 0; ring < 64; ++ring) {
    LidarPoint p;
    p.ring = static_cast<std::int16_t>(ring);
    full.points.push_back(p);
  }
  auto rings_after = [&](std::size_t frame) {
    Scan s = full;
    apply_beam_losses(sc, frame, 64, &s);
    std::vector<int> rings;
    for (const auto& p : s.points) rings.push_back(p.ring);
    return rings;
  };
  EXPECT_EQ(rings_after(9).size(), 64u);
  const auto every_other = rings_after(10);
  ASSERT_EQ(every_other.size(), 32u);
  for (int r : every_other) EXPECT_EQ(r % 2, 0);
  const auto lower = rings_after(29);
  ASSERT_EQ(lower.size(), 32u);
  EXPECT_EQ(lower.front(), 32);
  EXPECT_EQ(rings_after(30).size(), 64u);
}

TEST(DegenerateScenes, TunnelIsAClosedTubeInsideAndOpenOutside) {
  const Scenario sc = make_degenerate_scenario("tunnel", 1, 300);
  ASSERT_GT(sc.degenerate_end_frame, sc.degenerate_first_frame + 100);
  const Pose inside = sc.frame_pose((sc.degenerate_first_frame + sc.degenerate_end_frame) / 2);
  const Eigen::Vector3d o = inside.translation();
  RayHit hit;
  // Ceiling 6 m above the road, walls 8 m either side of the centerline (lane 1.6 m right).
  ASSERT_TRUE(sc.world.cast(o, Eigen::Vector3d::UnitZ(), 100, 1, &hit));
  EXPECT_NEAR(hit.range_m, 6.0 - 1.73, 0.05);
  ASSERT_TRUE(sc.world.cast(o, Eigen::Vector3d::UnitY(), 100, 2, &hit));
  EXPECT_NEAR(hit.range_m, 8.0 + 1.6, 0.05);
  // Before the tunnel the sky is open.
  EXPECT_FALSE(sc.world.cast(sc.frame_pose(2).translation(), Eigen::Vector3d::UnitZ(), 100, 3, &hit));
}

TEST(DegenerateScenes, UnknownNameIsAnErrorListingTheScenes) {
  try {
    make_degenerate_scenario("cave", 1, 100);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("tunnel"), std::string::npos);
  }
}
