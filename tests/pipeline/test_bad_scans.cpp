// The whole pipeline on broken scans in the middle of a good sequence: empty scans, a handful
// of points, all-NaN points, coordinates of 1e30, repeated and backwards timestamps. Every run
// must finish with one finite pose per frame (or a clear scfloam::Error), never crash.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <functional>
#include <limits>

#include "pipeline/run_quietly.hpp"
#include "pipeline/scan_list_source.hpp"
#include "scfloam/error.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/pipeline/pipeline.hpp"
#include "scfloam/sim/simulate.hpp"
#include "test_paths.hpp"

namespace scfloam {
namespace {

constexpr std::size_t kFrames = 30;

// A short simulated VLP-16 drive, simulated once per test program.
const std::vector<Scan>& good_scans() {
  static const std::vector<Scan> scans = [] {
    const auto dir = test::scratch_dir("bad_scans_seq_" + std::to_string(getpid()));
    sim::SimConfig cfg;
    cfg.frames = kFrames;
    cfg.sensor = "vlp16";
    cfg.traffic.oncoming_per_minute = 0;
    sim::simulate_sequence(cfg, dir, false);
    const auto seq = KittiSequence::open(dir);
    std::vector<Scan> out;
    for (std::size_t i = 0; i < seq.size(); ++i) out.push_back(seq.load(i));
    return out;
  }();
  return scans;
}

SlamConfig vlp16_config() {
  SlamConfig config;
  config.odometry.rings.lidar = "vlp16";
  config.odometry.rings.min_points_per_ring = 20;
  return config;
}

// Runs the pipeline in `mode` on the good sequence with `spoil` applied to frames [10, 13).
RunResult run_spoiled(SlamMode mode, const std::function<void(Scan&, std::size_t)>& spoil,
                      bool deterministic = true) {
  std::vector<Scan> scans = good_scans();
  for (std::size_t i = 10; i < 13; ++i) spoil(scans[i], i);
  test::ScanListSource source(std::move(scans));
  return test::run_quietly(source, mode, vlp16_config(), deterministic);
}

void expect_finite_trajectory(const RunResult& result) {
  ASSERT_EQ(result.T_world_lidar.size(), kFrames);
  ASSERT_EQ(result.odometry_T_world_lidar.size(), kFrames);
  for (std::size_t i = 0; i < kFrames; ++i) {
    EXPECT_TRUE(result.T_world_lidar[i].matrix().allFinite()) << "frame " << i;
    EXPECT_TRUE(result.odometry_T_world_lidar[i].matrix().allFinite()) << "frame " << i;
    // A spoiled frame may lose track, but not fling the vehicle kilometres away.
    EXPECT_LT(result.T_world_lidar[i].translation().norm(), 1000.0) << "frame " << i;
  }
}

struct Spoil {
  const char* name;
  std::function<void(Scan&, std::size_t)> apply;
};

std::vector<Spoil> spoils() {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  return {
      {"empty", [](Scan& s, std::size_t) { s.points.clear(); }},
      {"one point", [](Scan& s, std::size_t) { s.points.resize(1); }},
      {"ten points", [](Scan& s, std::size_t) { s.points.resize(10); }},
      {"all NaN",
       [nan](Scan& s, std::size_t) {
         for (auto& p : s.points) p.x = p.y = p.z = nan;
       }},
      {"half NaN",
       [nan](Scan& s, std::size_t) {
         for (std::size_t i = 0; i < s.points.size(); i += 2) s.points[i].z = nan;
       }},
      {"coordinates of 1e30",
       [](Scan& s, std::size_t) {
         for (auto& p : s.points) p.x = p.y = p.z = 1e30f;
       }},
      {"some coordinates of 1e30",
       [](Scan& s, std::size_t) {
         for (std::size_t i = 0; i < s.points.size(); i += 7) s.points[i].z = 1e30f;
       }},
      {"duplicate timestamps",
       [](Scan& s, std::size_t) { s.timestamp_s = 1.0; }},
      {"time going backwards", [](Scan& s, std::size_t i) { s.timestamp_s = 5.0 - 0.1 * i; }},
  };
}

TEST(BadScans, OdometryKeepsAFiniteTrajectory) {
  for (const auto& spoil : spoils()) {
    SCOPED_TRACE(spoil.name);
    try {
      expect_finite_trajectory(run_spoiled(SlamMode::kOdometry, spoil.apply));
    } catch (const Error& e) {
      ADD_FAILURE() << "error instead of riding through: " << e.what();
    }
  }
}

TEST(BadScans, LoopPipelineOnItsThreadsKeepsAFiniteTrajectory) {
  for (const auto& spoil : spoils()) {
    SCOPED_TRACE(spoil.name);
    try {
      expect_finite_trajectory(run_spoiled(SlamMode::kOptimized, spoil.apply, false));
    } catch (const Error& e) {
      ADD_FAILURE() << "error instead of riding through: " << e.what();
    }
  }
}

TEST(BadScans, EverySourceScanBrokenStillFinishes) {
  // Nothing usable at all: the run ends with identity-ish finite poses, not a crash.
  std::vector<Scan> scans(5);
  for (std::size_t i = 0; i < scans.size(); ++i) scans[i].timestamp_s = 0.1 * i;
  test::ScanListSource source(std::move(scans));
  RunOptions options;
  options.progress = false;
  const RunResult result = run_slam(source, vlp16_config(), options);
  ASSERT_EQ(result.T_world_lidar.size(), 5u);
  for (const auto& T : result.T_world_lidar) EXPECT_TRUE(T.matrix().allFinite());
}

// A source that raises the stop flag when frame `stop_at` is read (on the prefetch thread).
class StoppingSource final : public ScanSource {
 public:
  StoppingSource(const std::vector<Scan>& scans, std::size_t stop_at, std::atomic<bool>& stop)
      : scans_(scans), stop_at_(stop_at), stop_(stop) {}
  std::size_t size() const override { return scans_.size(); }
  Scan load(std::size_t index) const override {
    if (index == stop_at_) stop_ = true;
    return scans_.at(index);
  }
  std::string describe() const override { return "stopping test scans"; }

 private:
  const std::vector<Scan>& scans_;
  std::size_t stop_at_;
  std::atomic<bool>& stop_;
};

TEST(StopFlag, EndsTheRunEarlyWithACompleteResult) {
  for (const bool deterministic : {true, false}) {
    SCOPED_TRACE(deterministic ? "deterministic" : "threaded");
    std::atomic<bool> stop{false};
    StoppingSource source(good_scans(), 12, stop);
    RunOptions options;
    options.mode = SlamMode::kOptimized;
    options.progress = false;
    options.deterministic = deterministic;
    options.stop = &stop;
    const RunResult result = run_slam(source, vlp16_config(), options);
    EXPECT_TRUE(result.interrupted);
    // The prefetcher reads ahead, so the flag rises before the odometry reaches frame 12.
    EXPECT_GE(result.T_world_lidar.size(), 1u);
    EXPECT_LE(result.T_world_lidar.size(), 13u);
    EXPECT_EQ(result.odometry_T_world_lidar.size(), result.T_world_lidar.size());
    EXPECT_EQ(result.stamps_s.size(), result.T_world_lidar.size());
    EXPECT_EQ(result.keyframe_poses.size(), result.keyframe_frames.size());
    for (const auto& T : result.T_world_lidar) EXPECT_TRUE(T.matrix().allFinite());
  }
  // A flag that never rises changes nothing.
  std::atomic<bool> never{false};
  test::ScanListSource source(good_scans());
  RunOptions options;
  options.progress = false;
  options.stop = &never;
  const RunResult full = run_slam(source, vlp16_config(), options);
  EXPECT_FALSE(full.interrupted);
  EXPECT_EQ(full.T_world_lidar.size(), kFrames);
}

TEST(BadScans, EmptySourceIsAClearError) {
  test::ScanListSource source({});
  RunOptions options;
  options.progress = false;
  EXPECT_THROW(run_slam(source, vlp16_config(), options), Error);
}

}  // namespace
}  // namespace scfloam
