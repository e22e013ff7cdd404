// The whole system on the degenerate scenes of issue 8 (sim/degenerate.hpp): each run
// completes in both modes with finite poses, the degenerate frames are counted in the result
// (summary.json's degenerate_frames), and the error once structure returns is bounded.
// Each test simulates its scene into its own scratch folder (KITTI layout, as a user's input:
// no ring or point time survives the .bin files), removed when the test process ends.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>

#include "pipeline/run_quietly.hpp"
#include "scfloam/io/scan_source.hpp"
#include "scfloam/pipeline/outputs.hpp"
#include "scfloam/pipeline/pipeline.hpp"
#include "scfloam/se3.hpp"
#include "scfloam/sim/simulate.hpp"
#include "scfloam/stats.hpp"
#include "test_paths.hpp"

using namespace scfloam;
namespace fs = std::filesystem;

namespace {

struct Scene {
  fs::path dir;
  std::size_t first = 0, end = 0;  // the degenerate frames [first, end), from sim.yaml
};

Scene simulated(const std::string& name, std::size_t frames, bool traffic, std::uint64_t seed = 3) {
  Scene scene;
  scene.dir = test::scratch_dir("degenerate_" + name + "_" + std::to_string(frames) + "_seed" + std::to_string(seed));
  sim::SimConfig config;
  config.seed = seed;
  config.frames = frames;
  config.scenario = name;
  config.traffic.enabled = traffic;
  sim::simulate_sequence(config, scene.dir, false);
  std::FILE* f = std::fopen((scene.dir / "sim.yaml").c_str(), "r");
  char line[512];
  while (f && std::fgets(line, sizeof line, f))
    std::sscanf(line, "degenerate_frames: [%zu, %zu]", &scene.first, &scene.end);
  if (f) std::fclose(f);
  return scene;
}

bool finite(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

// Both modes complete, every pose is finite, summary.json carries degenerate_frames.
std::pair<RunResult, RunResult> run_both(const ScanSource& source) {
  RunResult odometry = test::run_quietly(source, SlamMode::kOdometry);
  RunResult optimized = test::run_quietly(source, SlamMode::kOptimized);
  for (const RunResult* r : {&odometry, &optimized}) {
    EXPECT_EQ(r->T_world_lidar.size(), source.size());
    for (std::size_t i = 0; i < r->T_world_lidar.size(); ++i) {
      EXPECT_TRUE(finite(r->T_world_lidar[i])) << mode_name(r->mode) << " frame " << i;
      EXPECT_TRUE(finite(r->odometry_T_world_lidar[i])) << mode_name(r->mode) << " frame " << i;
    }
    const auto summary = make_summary(source, *r);
    EXPECT_TRUE(summary.contains("degenerate_frames"));
  }
  // Memory stays sane: a few hundred frames of HDL-64 need well under 2 GB (the long-run
  // bench measures the growth per keyframe).
  EXPECT_LT(peak_rss_mb(), 2000.0);
  return {std::move(odometry), std::move(optimized)};
}

// Translation error of the estimated motion from frame a to frame b against ground truth.
double motion_error_m(const PoseList& est, const PoseList& gt, std::size_t a, std::size_t b) {
  const Eigen::Isometry3d d_est = est[a].inverse() * est[b], d_gt = gt[a].inverse() * gt[b];
  return (d_est.translation() - d_gt.translation()).norm();
}

// Largest frame-to-frame translation error over frames [a, b).
double worst_step_error_m(const PoseList& est, const PoseList& gt, std::size_t a, std::size_t b) {
  double worst = 0;
  for (std::size_t i = std::max<std::size_t>(a, 1); i < b; ++i) worst = std::max(worst, motion_error_m(est, gt, i - 1, i));
  return worst;
}

// What a constant-velocity motion model alone makes of frames a..b: the ground-truth motion of
// frame a (from a-1) repeated b-a times, against the true motion from a to b. A fallback that
// keeps the prediction along a weak direction can do no better than this from its entry.
double constant_velocity_error_m(const PoseList& gt, std::size_t a, std::size_t b) {
  const Eigen::Isometry3d step = gt[a - 1].inverse() * gt[a];
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (std::size_t i = a; i < b; ++i) T = T * step;
  return (T.translation() - (gt[a].inverse() * gt[b]).translation()).norm();
}

// The degenerate stretch [first, end) of a scene: its length, the estimate's error over it and
// the motion model's (constant velocity from its start).
struct Stretch {
  double length_m, error_m, model_error_m;
};
Stretch stretch_of(const Scene& scene, const PoseList& est, const PoseList& gt) {
  return {(gt[scene.end - 1].translation() - gt[scene.first].translation()).norm(),
          motion_error_m(est, gt, scene.first, scene.end - 1),
          constant_velocity_error_m(gt, scene.first, scene.end - 1)};
}

}  // namespace

// A straight tunnel: inside, scan matching cannot see motion along the axis. The odometry must
// flag it, stay finite, and after the exit track the motion again frame by frame.
TEST(Degenerate, TunnelIsFlaggedAndTheOdometryRecoversAfterTheExit) {
  const Scene scene = simulated("tunnel", 300, false);
  const auto source = open_scan_source(scene.dir);
  const PoseList gt = source->ground_truth_lidar();
  ASSERT_GT(scene.end, scene.first + 50);
  const auto [odometry, optimized] = run_both(*source);
  const PoseList& est = odometry.T_world_lidar;
  // Along the tunnel the bound is the motion model's own: constant velocity from the entry.
  // (The car accelerates from 11.6 to 13.5 m/s inside, so that is ~20 m over the ~210 m
  // tunnel; an estimate that stalls, as one held by a spurious constraint does, is ~210 m off.)
  const Stretch tunnel = stretch_of(scene, est, gt);
  std::printf("tunnel: %zu degenerate frames flagged of %zu inside; %.0f m inside, error over it %.2f m "
              "(constant velocity from the entry: %.2f m); worst step after exit %.3f m\n",
              odometry.degenerate_frames, scene.end - scene.first, tunnel.length_m, tunnel.error_m,
              tunnel.model_error_m, worst_step_error_m(est, gt, scene.end + 10, gt.size()));
  EXPECT_GE(odometry.degenerate_frames, (scene.end - scene.first) / 4);
  EXPECT_LT(tunnel.error_m, tunnel.model_error_m);
  // Recovered: 1 s after the exit, every frame's motion is right within 5 cm.
  EXPECT_LT(worst_step_error_m(est, gt, scene.end + 10, gt.size()), 0.05);
  EXPECT_LT(worst_step_error_m(optimized.T_world_lidar, gt, scene.end + 10, gt.size()), 0.05);
}

// A village street, ~170 m of flat open ground whose only structure is a far barn or a group
// of trees (45-110 m off the track), another village street. On the field, x, y and yaw are
// barely constrained: the odometry must flag it and weigh the motion model there against what
// little the matches see, rather than stall (before session 6 it stalled: ring-bound noise
// edges held every frame at the last one, error ~ the whole field).
TEST(Degenerate, OpenFieldIsFlaggedAndTheMotionModelCarriesTheEstimate) {
  const Scene scene = simulated("open-field", 300, false);
  const auto source = open_scan_source(scene.dir);
  const PoseList gt = source->ground_truth_lidar();
  ASSERT_GT(scene.end, scene.first + 100);
  const auto [odometry, optimized] = run_both(*source);
  const PoseList& est = odometry.T_world_lidar;
  const Stretch field = stretch_of(scene, est, gt);
  std::printf("open field: %zu degenerate frames flagged, %zu on the field; %.0f m of field, error over it "
              "%.2f m (constant velocity from its start: %.2f m); worst step in the first village %.3f m\n",
              odometry.degenerate_frames, scene.end - scene.first, field.length_m, field.error_m,
              field.model_error_m, worst_step_error_m(est, gt, 1, scene.first));
  EXPECT_GE(odometry.degenerate_frames, (scene.end - scene.first) / 4);
  EXPECT_LT(worst_step_error_m(est, gt, 1, scene.first), 0.05);
  // No worse than the motion model from the field's start, give or take the entry speed, which
  // is itself estimated (5 % of the field: a speed 5 % off). A stall is off by the whole field.
  const double bound = field.model_error_m + 0.05 * field.length_m;
  EXPECT_LT(field.error_m, bound);
  EXPECT_LT(stretch_of(scene, optimized.T_world_lidar, gt).error_m, bound);
  // After the field this world's second village is tracked frame by frame again (the next
  // test checks two more worlds).
  const double after = worst_step_error_m(est, gt, scene.end + 20, gt.size());
  std::printf("open field, seed 3: worst step from 2 s into the second village %.3f m\n", after);
  EXPECT_LT(after, 0.05);
}

// After the field, the second village is tracked frame by frame again. (Before session 7 the
// weak directions were frozen at the motion model: the second village of seeds 5 and 9 is
// itself weak by the condition ratio, 0.07-0.10, and rode the field's velocity error at
// 0.23-0.25 m per step to the end. docs/degenerate.md, "Session 7".)
TEST(Degenerate, OpenFieldRecoversInTheNextVillage) {
  // Two more worlds (the barns and villages differ); seed 3's is checked by the test above,
  // which has its odometry at hand.
  for (const std::uint64_t seed : {5, 9}) {
    const Scene scene = simulated("open-field", 300, false, seed);
    const auto source = open_scan_source(scene.dir);
    const PoseList gt = source->ground_truth_lidar();
    const RunResult odometry = test::run_quietly(*source, SlamMode::kOdometry);
    const double after = worst_step_error_m(odometry.T_world_lidar, gt, scene.end + 20, gt.size());
    std::printf("open field, seed %d: worst step from 2 s into the second village %.3f m\n",
                static_cast<int>(seed), after);
    EXPECT_LT(after, 0.05) << "seed " << seed;
    test::ScratchFolders::instance().remove(scene.dir);  // 0.5 GB each: one on disk at a time
  }
}

// A car standing still for 20 s with traffic passing around it: the estimate must not creep.
TEST(Degenerate, StationaryCarDoesNotDrift) {
  const Scene scene = simulated("stationary", 360, true);  // 20 s standing (the CLI default is 60 s)
  const auto source = open_scan_source(scene.dir);
  const PoseList gt = source->ground_truth_lidar();
  ASSERT_GT(scene.end, scene.first + 150);
  const RunResult odometry = test::run_quietly(*source, SlamMode::kOdometry);
  const RunResult optimized = test::run_quietly(*source, SlamMode::kOptimized);
  for (const RunResult* r : {&odometry, &optimized}) {
    const PoseList& est = r->T_world_lidar;
    ASSERT_EQ(est.size(), gt.size());
    const Eigen::Isometry3d still = est[scene.first].inverse() * est[scene.end - 1];
    std::printf("stationary (%s): drift over %.0f s standing %.4f m, %.4f deg\n", mode_name(r->mode).c_str(),
                (scene.end - 1 - scene.first) * 0.1, still.translation().norm(),
                rotation_angle_rad(still.linear()) * 180 / M_PI);
    EXPECT_LT(still.translation().norm(), 0.03);
    EXPECT_LT(rotation_angle_rad(still.linear()) * 180 / M_PI, 0.05);
    for (const auto& T : est) EXPECT_TRUE(finite(T));
  }
}

// 1 s of data missing: the stamps jump from k to k + 1.1 s while the car moves ~8 m. The
// prediction must use the real time step so that the first frame after the gap is matched.
TEST(Degenerate, GapOfOneSecondIsBridged) {
  const Scene scene = simulated("gap", 200, true);
  const auto source = open_scan_source(scene.dir);
  const PoseList gt = source->ground_truth_lidar();
  ASSERT_EQ(scene.end, scene.first + 1);
  const auto before = source->load(scene.first - 1).timestamp_s, after = source->load(scene.first).timestamp_s;
  EXPECT_NEAR(after - before, 1.1, 1e-6);
  const auto [odometry, optimized] = run_both(*source);
  const double jump_m = (gt[scene.first].translation() - gt[scene.first - 1].translation()).norm();
  const double across = motion_error_m(odometry.T_world_lidar, gt, scene.first - 1, scene.first);
  std::printf("gap: car moved %.2f m in the gap; error of that step %.3f m; worst step after %.3f m\n", jump_m,
              across, worst_step_error_m(odometry.T_world_lidar, gt, scene.first + 1, gt.size()));
  EXPECT_LT(across, 0.1);
  EXPECT_LT(motion_error_m(optimized.T_world_lidar, gt, scene.first - 1, scene.first), 0.1);
  EXPECT_LT(worst_step_error_m(odometry.T_world_lidar, gt, scene.first + 1, gt.size()), 0.05);
}

// Every other beam, then the upper half of the beams, missing for a quarter of the drive each.
// Half of an HDL-64's rings spread over its whole field of view still see the street: every
// step stays within 5 cm. The upper half gone leaves the lower block (-8 to -25 deg), which
// sees the ground within ~12 m and the lowest metre of nearby walls: x and y are barely
// constrained (eigenvalues 3-25 against ~1000 normally, measured), so only the motion model
// knows the motion there, and the car accelerates from 5.3 to 9 m/s in those 5 s. The bound is
// the one of the open field: no worse than constant velocity from the quarter's start, give
// or take 5 % of its length. When the beams return the first full frame re-registers to the
// map seen before (a correction of ~0.4 m in one step, measured); 1 s later every step is
// within 5 cm again.
TEST(Degenerate, HalfTheBeamsMissingKeepsTracking) {
  const Scene scene = simulated("half-beams", 200, true);
  const auto source = open_scan_source(scene.dir);
  const PoseList gt = source->ground_truth_lidar();
  ASSERT_EQ(scene.end - scene.first, 100u);  // [N/4, N/2) odd rings, [N/2, 3N/4) upper half
  const std::size_t upper_half = scene.first + 50;
  const auto [odometry, optimized] = run_both(*source);
  for (const RunResult* r : {&odometry, &optimized}) {
    const PoseList& est = r->T_world_lidar;
    const double odd_rings = worst_step_error_m(est, gt, scene.first, upper_half);
    const Stretch lower = stretch_of(Scene{scene.dir, upper_half, scene.end}, est, gt);
    const double after = worst_step_error_m(est, gt, scene.end + 10, gt.size());
    std::printf("half beams (%s): %zu degenerate frames; odd rings: worst step %.3f m; lower block only: "
                "%.1f m, error %.2f m (constant velocity: %.2f m); worst step from 1 s after %.3f m\n",
                mode_name(r->mode).c_str(), r->degenerate_frames, odd_rings, lower.length_m, lower.error_m,
                lower.model_error_m, after);
    EXPECT_LT(odd_rings, 0.05);
    EXPECT_LT(lower.error_m, lower.model_error_m + 0.05 * lower.length_m);
    EXPECT_LT(after, 0.05);
  }
  EXPECT_GE(odometry.degenerate_frames, 25u);  // the lower-block frames are flagged
}
