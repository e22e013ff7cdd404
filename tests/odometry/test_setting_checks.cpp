// The odometry's setting checks (PreprocessConfig::deskew_check, elevation_check): where the
// other setting fits better the odometry switches to its shadow and revises the trial's frames
// with the shadow's results, so that the trajectory is the one the winning setting makes from
// the trial's first frame on, without a jump. Short (40-50 frames) so that they also run under
// the sanitizers; the accuracy of the checks on whole drives is SimOdometry.DeskewCheck... and
// SimOdometry.ElevationCheck... .
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "odometry/rendered_drive.hpp"
#include "scfloam/config.hpp"
#include "scfloam/odometry/odometry.hpp"
#include "scfloam/sim/scan.hpp"
#include "scfloam/sim/simulate.hpp"

namespace scfloam {
namespace {

// The worst error of a frame-to-frame step over a 40-frame drive (frames 2..), and the frame
// at which `switched(odometry)` first held; the poses as a caller that takes the revisions
// (OdometryResult::revised) keeps them.
struct SwitchRun {
  double worst_step_error_m = 0;
  std::size_t switched_at = 0;
  std::size_t revised_frames = 0;  // on the switch frame
  std::vector<Eigen::Isometry3d> poses;
  std::vector<double> feature_sums;  // per frame: the sum of its edge and plane coordinates
};

double feature_sum(const OdometryResult& r) {
  double sum = 0;
  for (const FeatureCloud* cloud : {&r.edges, &r.planes})
    for (const Eigen::Vector3f& p : *cloud) sum += p.cast<double>().sum();
  return sum;
}

using test::RenderedDrive;

// A short drive on the loops route (seed 23); `calibrated_beams`: an HDL-64E without KITTI's
// elevation error. Rendered once per process: a test runs the checked odometry and the one
// configured as the check chose on the same scans.
const RenderedDrive& short_drive(std::size_t frames, bool calibrated_beams) {
  static std::map<std::pair<std::size_t, bool>, RenderedDrive> drives;
  const auto key = std::make_pair(frames, calibrated_beams);
  if (const auto it = drives.find(key); it != drives.end()) return it->second;
  sim::SimConfig cfg;
  cfg.route = "loops";
  cfg.frames = frames;
  cfg.seed = 23;
  if (calibrated_beams) cfg.elevation_bias_deg = 0;
  return drives.emplace(key, test::render_drive(cfg)).first->second;
}

// `after_frame(k, odometry, result)`, when given, runs after each frame.
template <typename Switched>
SwitchRun drive_through_switch(
    const RenderedDrive& drive, Odometry& odometry, Switched switched,
    const std::function<void(std::size_t, Odometry&, const OdometryResult&)>& after_frame = {}) {
  const std::vector<Eigen::Isometry3d>& gt = drive.gts;
  const std::size_t frames = drive.scans.size();
  SwitchRun run;
  for (std::size_t k = 0; k < frames; ++k) {
    const Scan& scan = drive.scans[k];
    const OdometryResult result = odometry.process(scan);
    EXPECT_LE(result.revised.size(), k);
    for (std::size_t i = 0; i < result.revised.size(); ++i) {
      run.poses.at(k - result.revised.size() + i) = result.revised[i].T_world_lidar;
      run.feature_sums.at(k - result.revised.size() + i) = feature_sum(result.revised[i]);
    }
    run.poses.push_back(result.T_world_lidar);
    run.feature_sums.push_back(feature_sum(result));
    if (run.switched_at == 0 && switched(odometry)) {
      run.switched_at = k;
      run.revised_frames = result.revised.size();
    }
    if (after_frame) after_frame(k, odometry, result);
  }
  for (std::size_t k = 2; k < frames; ++k) {
    const Eigen::Isometry3d e = (gt[k - 1].inverse() * gt[k]).inverse() * (run.poses[k - 1].inverse() * run.poses[k]);
    run.worst_step_error_m = std::max(run.worst_step_error_m, e.translation().norm());
  }
  return run;
}

// The check switched to the shadow at the frame it reports, on a full window of frames that
// clearly favoured the shadow, and revised the trial's earlier frames (the trial began at
// `trial_start`), without a jump in the reported track.
void expect_switch(const SettingCheck& check, const SwitchRun& run, const char* verdict,
                   std::size_t trial_start) {
  EXPECT_EQ(check.verdict, verdict);
  EXPECT_GT(run.switched_at, 5u);
  EXPECT_EQ(check.decided_at_frame, run.switched_at);
  EXPECT_EQ(run.revised_frames, run.switched_at - trial_start);
  EXPECT_GT(check.residual_ratio, 1.05);
  EXPECT_GE(check.frames_compared, 15u);
  std::printf("  switched at frame %zu, worst step error %.4f m\n", run.switched_at, run.worst_step_error_m);
  EXPECT_LT(run.worst_step_error_m, 0.03) << "switched at frame " << run.switched_at;
}

// The same drive with the odometry configured as the check chose from the start, and no check:
// where the trial began at frame 0, the revised track and features are exactly that one's.
void expect_same_track_as(const OdometryConfig& chosen, const RenderedDrive& drive, const SwitchRun& checked) {
  Odometry odometry(chosen);
  const SwitchRun plain = drive_through_switch(drive, odometry, [](const Odometry&) { return false; });
  ASSERT_EQ(plain.poses.size(), checked.poses.size());
  double worst_m = 0;
  for (std::size_t k = 0; k < plain.poses.size(); ++k)
    worst_m = std::max(worst_m, (plain.poses[k].matrix() - checked.poses[k].matrix()).cwiseAbs().maxCoeff());
  EXPECT_LT(worst_m, 1e-9);
  EXPECT_EQ(plain.feature_sums, checked.feature_sums);
}

TEST(DeskewCheck, CompensatedScansSwitchToTheRawOdometryWithoutAJump) {
  OdometryConfig config;
  config.preprocess.deskew = true;  // the scans carry times, but are compensated (KITTI-like)
  Odometry odometry(config);
  EXPECT_EQ(odometry.deskew_check().verdict, "off");  // nothing seen yet
  const SwitchRun run = drive_through_switch(short_drive(40, false), odometry, [](const Odometry& o) {
    return o.deskew_check().verdict == "compensated";
  });
  expect_switch(odometry.deskew_check(), run, "compensated", 0);
  // KITTI-like beams: the elevation check that follows keeps the correction (or is still
  // measuring: either way this odometry's poses are the corrected ones).
  EXPECT_NE(odometry.elevation_check().verdict, "no offset");
  OdometryConfig raw = config;
  raw.preprocess.deskew = false;
  raw.preprocess.elevation_check = false;
  expect_same_track_as(raw, short_drive(40, false), run);
}

// Calibrated HDL-64E beams, run with KITTI's correction: the odometry continues without it.
TEST(ElevationCheck, CalibratedBeamsSwitchToTheUncorrectedOdometryWithoutAJump) {
  Odometry odometry(OdometryConfig{});  // KITTI's 0.22 deg
  EXPECT_EQ(odometry.elevation_check().verdict, "off");  // nothing seen yet
  const SwitchRun run = drive_through_switch(short_drive(40, true), odometry, [](const Odometry& o) {
    return o.elevation_check().verdict == "no offset";
  });
  expect_switch(odometry.elevation_check(), run, "no offset", 0);
  EXPECT_EQ(odometry.deskew_check().verdict, "off");
  OdometryConfig uncorrected;
  uncorrected.preprocess.elevation_correction_deg = 0;
  expect_same_track_as(uncorrected, short_drive(40, true), run);
}

// Both checks configured: the deskew check runs first (whether the scans are distorted
// changes every residual the elevation check compares), then the elevation check, in the
// odometry the first one chose; the frames keep their index in the decisions.
TEST(ElevationCheck, WaitsForTheDeskewCheckThenRunsInTheOdometryItChose) {
  const RenderedDrive& drive = short_drive(50, true);  // two trials: the second decides at ~frame 39
  OdometryConfig config;
  config.preprocess.deskew = true;  // the scans carry times, but are compensated
  Odometry odometry(config);
  bool waited = false;
  const SwitchRun run = drive_through_switch(drive, odometry, [&](const Odometry& o) {
    if (o.deskew_check().verdict == "trial") waited = o.elevation_check().verdict == "waiting";
    return o.elevation_check().verdict == "no offset";
  });
  EXPECT_TRUE(waited);
  EXPECT_EQ(odometry.deskew_check().verdict, "compensated");
  EXPECT_EQ(odometry.elevation_check().verdict, "no offset");
  EXPECT_EQ(odometry.elevation_check().decided_at_frame, run.switched_at);
  EXPECT_GT(run.switched_at, odometry.deskew_check().decided_at_frame + 15);
  // The elevation trial began on the frame after the deskew verdict.
  EXPECT_EQ(run.revised_frames, run.switched_at - odometry.deskew_check().decided_at_frame - 1);
  // Two switches, the second from an odometry already re-anchored once.
  std::printf("  switched at frame %zu, worst step error %.4f m\n", run.switched_at, run.worst_step_error_m);
  EXPECT_LT(run.worst_step_error_m, 0.03);
}

// A loop closure rebuilds the odometry's map from keyframes during a trial: the two maps are no
// longer grown alike, so the shadow starts again rather than compare against a thinned map.
TEST(ElevationCheck, AMapRebuiltDuringTheTrialStartsTheShadowAgain) {
  const RenderedDrive& drive = short_drive(50, true);  // the restarted trial decides at ~frame 30
  Odometry odometry(OdometryConfig{});
  std::vector<Eigen::Isometry3d> poses;
  std::vector<FeatureCloud> edges, planes;
  constexpr std::size_t kResetAt = 10;
  const SwitchRun run = drive_through_switch(
      drive, odometry, [](const Odometry& o) { return o.elevation_check().verdict == "no offset"; },
      [&](std::size_t k, Odometry& o, const OdometryResult& r) {
        poses.push_back(r.T_world_lidar);
        edges.push_back(r.edges);
        planes.push_back(r.planes);
        if (k != kResetAt) return;
        EXPECT_EQ(o.elevation_check().verdict, "trial");
        std::vector<std::pair<Eigen::Isometry3d, const FeatureCloud*>> e, p;
        for (std::size_t i = 0; i <= k; i += 2) e.emplace_back(poses[i], &edges[i]), p.emplace_back(poses[i], &planes[i]);
        o.reset_map(e, p, r.T_world_lidar);
      });
  const SettingCheck& check = odometry.elevation_check();
  EXPECT_EQ(check.verdict, "no offset");
  std::printf("  switched at frame %zu, worst step error %.4f m\n", run.switched_at, run.worst_step_error_m);
  // The new shadow's first five frames and then a full window: not before frame 10 + 5 + 15.
  EXPECT_GE(run.switched_at, kResetAt + 5 + 15);
  // Only the restarted shadow's frames (from the frame after the rebuild) are revised.
  EXPECT_EQ(run.revised_frames, run.switched_at - kResetAt - 1);
  EXPECT_LT(run.worst_step_error_m, 0.03);
}

// The two checks' verdicts after one (empty) scan with this config: (deskew, elevation).
std::pair<std::string, std::string> verdicts_after_one_scan(const OdometryConfig& config, bool timed) {
  Odometry odometry(config);
  Scan scan;
  scan.has_time = timed;
  odometry.process(scan);
  return {odometry.deskew_check().verdict, odometry.elevation_check().verdict};
}

TEST(ElevationCheck, OffWithoutACorrectionOrWithAnOnlineEstimateAndUncheckedWhenAsked) {
  OdometryConfig config;
  EXPECT_EQ(verdicts_after_one_scan(config, false).second, "trial");
  config.preprocess.elevation_correction_deg = 0;
  EXPECT_EQ(verdicts_after_one_scan(config, false).second, "off");
  config.preprocess.elevation_correction_deg = 0.22;
  config.preprocess.ground_elevation_calibration = true;
  EXPECT_EQ(verdicts_after_one_scan(config, false).second, "off");
  config.preprocess.ground_elevation_calibration = false;
  config.preprocess.elevation_check = false;
  EXPECT_EQ(verdicts_after_one_scan(config, false).second, "unchecked");
}

TEST(DeskewCheck, OffWithoutDeskewAndUncheckedWhenAsked) {
  OdometryConfig config;
  EXPECT_EQ(verdicts_after_one_scan(config, true).first, "off");
  config.preprocess.deskew = true;
  EXPECT_EQ(verdicts_after_one_scan(config, false).first, "no per-point times");
  // Timed scans: the deskew check's trial, the elevation check's wait for it.
  EXPECT_EQ(verdicts_after_one_scan(config, true), std::make_pair(std::string("trial"), std::string("waiting")));
  config.preprocess.deskew_check = false;
  EXPECT_EQ(verdicts_after_one_scan(config, true).first, "unchecked");
}

}  // namespace
}  // namespace scfloam
