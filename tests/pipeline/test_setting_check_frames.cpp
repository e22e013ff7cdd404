// The pipeline holds the frames of a running setting check (PreprocessConfig::elevation_check,
// deskew_check) and takes the winning setting's results for them, so that neither the
// trajectory nor the keyframes carry the setting the check dropped: on calibrated HDL-64E beams,
// where the check drops KITTI's elevation correction, a run is exactly the run configured
// without it.
#include <gtest/gtest.h>

#include <vector>

#include "pipeline/run_quietly.hpp"
#include "pipeline/scan_list_source.hpp"
#include "scfloam/pipeline/pipeline.hpp"
#include "scfloam/sim/scan.hpp"
#include "scfloam/sim/simulate.hpp"

using namespace scfloam;

namespace {

// A short drive on the loops route (seed 23) with calibrated HDL-64E beams (no KITTI offset).
test::ScanListSource calibrated_drive(std::size_t frames) {
  sim::SimConfig cfg;
  cfg.route = "loops";
  cfg.frames = frames;
  cfg.seed = 23;
  cfg.elevation_bias_deg = 0;
  const sim::SensorModel sensor = sim::sensor_for(cfg);
  const sim::Scenario sc = sim::build_scenario(cfg);
  const sim::BeamCalibration calib = sim::draw_beam_calibration(sensor, cfg.seed);
  std::vector<Scan> scans;
  for (std::size_t k = 0; k < sc.frames; ++k) scans.push_back(sim::render_frame(sc, sensor, calib, cfg, k));
  return test::ScanListSource(std::move(scans));
}

void expect_same_run(const RunResult& a, const RunResult& b) {
  ASSERT_EQ(a.T_world_lidar.size(), b.T_world_lidar.size());
  for (std::size_t i = 0; i < a.T_world_lidar.size(); ++i) {
    EXPECT_TRUE(a.T_world_lidar[i].matrix() == b.T_world_lidar[i].matrix()) << "frame " << i;
    EXPECT_TRUE(a.odometry_T_world_lidar[i].matrix() == b.odometry_T_world_lidar[i].matrix()) << "frame " << i;
  }
  EXPECT_EQ(a.keyframe_frames, b.keyframe_frames);
  EXPECT_EQ(a.elevation_correction_first_deg, b.elevation_correction_first_deg);
}

}  // namespace

TEST(SettingCheckFrames, ASwitchGivesTheRunConfiguredWithTheWinningSetting) {
  const test::ScanListSource source = calibrated_drive(40);
  const SlamConfig checked;  // KITTI's 0.22 deg, checked
  SlamConfig uncorrected;
  uncorrected.odometry.preprocess.elevation_correction_deg = 0;
  for (SlamMode mode : {SlamMode::kOdometry, SlamMode::kOptimized, SlamMode::kSimpleSc}) {
    SCOPED_TRACE(mode_name(mode));
    const RunResult a = test::run_quietly(source, mode, checked);
    ASSERT_EQ(a.elevation_check.verdict, "no offset");
    EXPECT_GT(a.elevation_check.decided_at_frame, 5u);
    EXPECT_GE(a.keyframe_frames.size(), 3u);  // some were cut from the trial's frames
    EXPECT_LT(a.keyframe_frames.at(1), a.elevation_check.decided_at_frame);
    EXPECT_EQ(a.elevation_correction_first_deg, 0.0);
    expect_same_run(a, test::run_quietly(source, mode, uncorrected));
  }
  // The loop stages on their threads get the held keyframes in one burst when the check
  // decides; with no lag allowed the run is still the deterministic one.
  SlamConfig threaded = checked;
  threaded.pipeline.max_loop_lag_frames = 0;
  expect_same_run(test::run_quietly(source, SlamMode::kOptimized, checked),
                  test::run_quietly(source, SlamMode::kOptimized, threaded, false));
}

// The input ends before the check decides: the held frames keep the configured setting, as an
// undecided check does, and the run is the one configured without the check.
TEST(SettingCheckFrames, AnInputThatEndsDuringTheTrialKeepsTheConfiguredSetting) {
  const test::ScanListSource source = calibrated_drive(12);
  const SlamConfig checked;
  SlamConfig unchecked;
  unchecked.odometry.preprocess.elevation_check = false;
  const RunResult a = test::run_quietly(source, SlamMode::kOptimized, checked);
  EXPECT_EQ(a.elevation_check.verdict, "trial");
  EXPECT_GT(a.elevation_correction_first_deg, 0.2);
  expect_same_run(a, test::run_quietly(source, SlamMode::kOptimized, unchecked));
}
