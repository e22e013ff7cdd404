// End to end: odometry on a short simulated city drive (rendered in memory) against its
// ground truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <vector>

#include "odometry/rendered_drive.hpp"
#include "test_paths.hpp"
#include "scfloam/config.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/io/trajectory.hpp"
#include "scfloam/odometry/odometry.hpp"
#include "scfloam/se3.hpp"
#include "scfloam/sim/scan.hpp"
#include "scfloam/sim/simulate.hpp"

namespace scfloam {
namespace {

constexpr std::size_t kAttitudeFrom = 30;

struct Drift {
  double path_m = 0;
  double end_error_m = 0;
  double first_frame_error_m = 0;  // frame 1 starts from a zero-velocity guess at full speed
  double max_frame_error_m = 0;    // frames 2..
  // Attitude drift: the angle between the true and the estimated "up" seen from the sensor
  // (yaw left out), worst over the frames after kAttitudeFrom, both trajectories re-anchored
  // at that frame: how the tilt grows once the map has formed, not what the first frames
  // left (sparse sensors start with a fixed tilt of a few tenths of a degree, a separate
  // matter, docs/odometry.md).
  double max_tilt_drift_deg = 0;
};

// `use_rings`: whether the odometry sees the scans' ring field. `rings`, `deskew`,
// `elevation`: what the odometry decided, after the run.
Drift run_sim(const test::RenderedDrive& drive, const OdometryConfig& odo_cfg, bool use_rings,
              RingLayoutInfo* rings = nullptr, SettingCheck* deskew = nullptr,
              SettingCheck* elevation = nullptr) {
  Odometry odometry(odo_cfg);
  Drift d;
  const std::vector<Eigen::Isometry3d>& gts = drive.gts;
  std::vector<Eigen::Isometry3d> ests;
  const std::size_t frames = drive.scans.size();
  for (std::size_t k = 0; k < frames; ++k) {
    OdometryResult result;
    if (use_rings || !drive.scans[k].has_ring) {
      result = odometry.process(drive.scans[k]);
    } else {
      Scan scan = drive.scans[k];
      scan.has_ring = false;
      result = odometry.process(scan);
    }
    // A setting check that switched replaces its trial's frames, as the pipeline does.
    for (std::size_t i = 0; i < result.revised.size(); ++i)
      ests.at(k - result.revised.size() + i) = result.revised[i].T_world_lidar;
    ests.push_back(result.T_world_lidar);
  }
  Eigen::Isometry3d prev_gt, prev_est, gt_anchor, est_anchor;
  for (std::size_t k = 0; k < frames; ++k) {
    const Eigen::Isometry3d& est = ests[k];
    const Eigen::Isometry3d& gt = gts[k];
    if (k > 0) {
      d.path_m += (gt.translation() - prev_gt.translation()).norm();
      const Eigen::Isometry3d e = (prev_gt.inverse() * gt).inverse() * (prev_est.inverse() * est);
      if (k == 1) d.first_frame_error_m = e.translation().norm();
      else d.max_frame_error_m = std::max(d.max_frame_error_m, e.translation().norm());
    }
    d.end_error_m = (gt.inverse() * est).translation().norm();
    if (k == kAttitudeFrom) {
      gt_anchor = gt;
      est_anchor = est;
    } else if (k > kAttitudeFrom) {
      // World up in the anchor frame's sensor axes, then seen from frame k along each chain.
      const Eigen::Vector3d up = gt_anchor.linear().transpose() * drive.world_up;
      const Eigen::Vector3d up_gt = (gt_anchor.inverse() * gt).linear().transpose() * up;
      const Eigen::Vector3d up_est = (est_anchor.inverse() * est).linear().transpose() * up;
      d.max_tilt_drift_deg = std::max(
          d.max_tilt_drift_deg, std::atan2(up_gt.cross(up_est).norm(), up_gt.dot(up_est)) * 180 / M_PI);
    }
    prev_gt = gt;
    prev_est = est;
  }
  if (rings) *rings = odometry.ring_layout();
  if (deskew) *deskew = odometry.deskew_check();
  if (elevation) *elevation = odometry.elevation_check();
  std::printf("  %s, %zu frames: path %.1f m, end-point error %.3f m (%.3f %%), frame 1 error "
              "%.3f m, max later frame error %.3f m, max tilt drift %.3f deg\n",
              drive.route.c_str(), frames, d.path_m, d.end_error_m, 100 * d.end_error_m / d.path_m,
              d.first_frame_error_m, d.max_frame_error_m, d.max_tilt_drift_deg);
  return d;
}

// A drive on the loops route with this sensor.
sim::SimConfig loops_drive(const std::string& sensor, std::size_t frames, std::uint64_t seed) {
  sim::SimConfig cfg;
  cfg.sensor = sensor;
  cfg.route = "loops";
  cfg.frames = frames;
  cfg.seed = seed;
  return cfg;
}

// config/NAME.yaml's odometry section (tests/odometry/this_file.cpp -> repository root).
OdometryConfig shipped_preset(const std::string& name) {
  const auto root = std::filesystem::path(__FILE__).parent_path().parent_path().parent_path();
  return load_config(root / "config" / (name + ".yaml")).odometry;
}

TEST(SimOdometry, StraightAvenueDriftBelowOnePercent) {
  sim::SimConfig cfg;
  cfg.route = "straight";
  cfg.frames = 60;
  cfg.seed = 7;
  const Drift d = run_sim(test::render_drive(cfg), OdometryConfig{}, /*use_rings=*/false);
  EXPECT_GT(d.path_m, 40.0);
  EXPECT_LT(d.end_error_m / d.path_m, 0.01);
  EXPECT_LT(d.first_frame_error_m, 0.2);
  EXPECT_LT(d.max_frame_error_m, 0.03);
}

TEST(SimOdometry, DistortedScansWithDeskewAndRingField) {
  sim::SimConfig cfg;
  cfg.route = "loops";
  cfg.frames = 40;
  cfg.seed = 3;
  cfg.motion_distortion = true;
  OdometryConfig odo;
  odo.preprocess.deskew = true;
  const Drift d = run_sim(test::render_drive(cfg), odo, /*use_rings=*/true);
  EXPECT_LT(d.end_error_m / d.path_m, 0.01);
  // Frames 0-1 come before any velocity; frame 2 puts them into the map again, deskewed.
  // Measured: every later frame within 4 mm (end point 1.0 cm); when they stayed in the map
  // as scanned, the next frames erred by up to 2.0 cm (end point 2.3 cm, docs/odometry.md).
  EXPECT_LT(d.max_frame_error_m, 0.01);
}

// A raw VLP-16 drive (motion-distorted sweeps with point times), rendered once per process.
const test::RenderedDrive& distorted_vlp16_drive() {
  static const test::RenderedDrive drive = [] {
    sim::SimConfig cfg = loops_drive("vlp16", 100, 19);
    cfg.motion_distortion = true;
    return test::render_drive(cfg);
  }();
  return drive;
}

// Scans with per-point times are deskewed only if they prove motion-distorted: some drivers and
// datasets compensate the motion and keep the time field (the simulator's scans carry times
// either way). The odometry runs without deskew alongside until the two solves' residuals
// agree on which fits (PreprocessConfig::deskew_check).
TEST(SimOdometry, DeskewCheckTellsDistortedFromCompensatedScans) {
  sim::SimConfig cfg = loops_drive("vlp16", 100, 19);
  const OdometryConfig preset = shipped_preset("vlp16");  // deskew on, check on
  ASSERT_TRUE(preset.preprocess.deskew && preset.preprocess.deskew_check);
  OdometryConfig forced = preset, off = preset;
  forced.preprocess.deskew_check = false;
  off.preprocess.deskew = false;

  const test::RenderedDrive& distorted_drive = distorted_vlp16_drive();
  SettingCheck check;
  const Drift distorted = run_sim(distorted_drive, preset, true, nullptr, &check);
  EXPECT_EQ(check.verdict, "distorted");
  EXPECT_LT(check.residual_ratio, 0.95);
  const Drift distorted_forced = run_sim(distorted_drive, forced, true);
  // The deskewed odometry is the one reported throughout: the check changes nothing here.
  EXPECT_EQ(distorted.end_error_m, distorted_forced.end_error_m);

  cfg.motion_distortion = false;
  const test::RenderedDrive compensated_drive = test::render_drive(cfg);
  const Drift compensated = run_sim(compensated_drive, preset, true, nullptr, &check);
  EXPECT_EQ(check.verdict, "compensated");
  EXPECT_GT(check.residual_ratio, 1.05);
  EXPECT_LT(check.decided_at_frame, 60u);
  const Drift compensated_forced = run_sim(compensated_drive, forced, true);
  const Drift compensated_off = run_sim(compensated_drive, off, true);
  // Deskewing compensated scans again puts each frame's motion off by up to 2.4 cm (1.0 cm
  // without deskew, measured); with the check the whole track is the raw odometry's (the
  // trial began at frame 0 and its frames were revised).
  EXPECT_GT(compensated_forced.max_frame_error_m, 1.8 * compensated_off.max_frame_error_m);
  EXPECT_EQ(compensated.max_frame_error_m, compensated_off.max_frame_error_m);
  EXPECT_EQ(compensated.end_error_m, compensated_off.end_error_m);
}

// Compensated scans that straight driving cannot tell from distorted ones: on the HDL-32E world
// of seed 11 (`scfloam simulate`, .bin, with traffic) the deskewed solve's residuals were 5-6 %
// lower than the shadow's over frames 15-30 (median ratio 0.949), the check kept deskew at frame
// 31, and from the first turn the deskewed compensated sweeps broke the track (0.66 % t_err over
// 600 frames). The drive rendered here (no traffic, the simulator's point times) does the same.
// Keeping deskew now needs a 10 % margin; the turn at frame ~57 then shows the scans compensated
// (docs/odometry.md, "Session 39"). Measured over these 90 frames: "compensated" at frame 59, median ratio 1.051,
// worst frame 0.008 m, end point 0.09 m; with the old 5 % margin "distorted" at frame 29 (0.941),
// worst frame 0.043 m, end point 0.36 m.
TEST(SimOdometry, DeskewCheckWaitsForClearEvidenceBeforeKeepingDeskew) {
  const sim::SimConfig cfg = loops_drive("hdl32", 600, 11);
  const OdometryConfig preset = shipped_preset("hdl32");  // deskew on, check on
  ASSERT_TRUE(preset.preprocess.deskew && preset.preprocess.deskew_check);
  OdometryConfig off = preset;
  off.preprocess.deskew = false;
  const test::RenderedDrive drive = test::render_drive(cfg, false, 90);
  SettingCheck check;
  const Drift checked = run_sim(drive, preset, /*use_rings=*/true, nullptr, &check);
  std::printf("  deskew check: %s at frame %zu, median ratio %.3f\n", check.verdict.c_str(),
              check.decided_at_frame, check.residual_ratio);
  EXPECT_EQ(check.verdict, "compensated");
  EXPECT_GT(check.residual_ratio, 1.0);
  // Once switched, the track is the undeskewed odometry's from the first frame.
  const Drift raw = run_sim(drive, off, /*use_rings=*/true);
  EXPECT_EQ(checked.end_error_m, raw.end_error_m);
  EXPECT_LT(checked.max_frame_error_m, 0.03);
}

// A robot that drives, stops and spins twice on the spot at 180 deg/s (18 deg per sweep),
// reaching that rate in 0.4 s, then drives off: while the rate changes, a sweep deskewed at
// the last interval's velocity is off by degrees at its ends, the solve fails and the map
// takes the failed frames. Deskewed again at its own solve's velocity
// (PreprocessConfig::redeskew) it is tracked through the spin's start and end.
constexpr double kSpinDriveOffS = 12;

// A VLP-16 drive along these sensor poses (10 Hz) in the world the simulator lays along them
// (`scfloam simulate --replay`); `first_frames` > 0 renders only those.
test::RenderedDrive replayed_vlp16_drive(const PoseList& lidar, const std::string& name, std::uint64_t seed,
                                         bool motion_distortion, std::size_t first_frames = 0) {
  const auto dir = test::scratch_dir(name);
  write_kitti_poses(dir / "poses.txt", lidar_to_camera_poses(lidar, kitti_default_Tr()));
  sim::SimConfig cfg;
  cfg.sensor = "vlp16";
  cfg.route = "kitti";
  cfg.replay_poses = dir / "poses.txt";
  cfg.frames = 0;
  cfg.seed = seed;
  cfg.motion_distortion = motion_distortion;
  return test::render_drive(cfg, false, first_frames);
}

test::RenderedDrive spinning_robot_drive() {
  PoseList lidar;
  const double rate = M_PI, ramp_s = 0.4, spin_s = 4 * M_PI / rate + ramp_s;  // two turns
  const double stop_s = 10.5, end_s = stop_s + 0.5 + spin_s + kSpinDriveOffS;
  const auto smooth = [](double x) {
    x = std::clamp(x, 0.0, 1.0);
    return x * x * (3 - 2 * x);
  };
  double x = 0, y = 0, yaw = 0;
  for (int i = 0; 0.01 * i <= end_s + 1e-9; ++i) {  // 100 Hz, every tenth pose kept
    const double t = 0.01 * i;
    if (i % 10 == 0) {
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      T.translation() = Eigen::Vector3d(x, y, 0);
      lidar.push_back(T);
    }
    // 10 m/s for 8 s, braking to a stop by 10.5 s, the spin from 11 s, then 8 m/s again.
    const double s = t - stop_s - 0.5;
    const double speed = t < 8 ? 10.0 : t < stop_s ? 10.0 * (1 - smooth((t - 8) / 2.5)) : s <= spin_s ? 0.0
                                                                                       : 8.0 * smooth((s - spin_s) / 3);
    const double turn = s >= 0 && s <= spin_s ? rate * std::min(smooth(s / ramp_s), smooth((spin_s - s) / ramp_s)) : 0.0;
    x += speed * std::cos(yaw) * 0.01;
    y += speed * std::sin(yaw) * 0.01;
    yaw += turn * 0.01;
  }
  return replayed_vlp16_drive(lidar, "spinning_robot", 12, true);
}

// The worst error of one frame's rotation (deg) against the ground truth.
double max_frame_rotation_error_deg(const test::RenderedDrive& drive, const OdometryConfig& config) {
  Odometry odometry(config);
  std::vector<Eigen::Isometry3d> ests;
  for (const Scan& scan : drive.scans) ests.push_back(odometry.process(scan).T_world_lidar);
  double worst = 0;
  for (std::size_t k = 1; k < ests.size(); ++k) {
    const Eigen::Isometry3d e = (drive.gts[k - 1].inverse() * drive.gts[k]).inverse() * (ests[k - 1].inverse() * ests[k]);
    worst = std::max(worst, so3_log(e.linear()).norm() * 180 / M_PI);
  }
  return worst;
}

TEST(SimOdometry, ASpinningRobotIsTrackedThroughTheSpinsStartAndEnd) {
  const test::RenderedDrive drive = spinning_robot_drive();
  OdometryConfig config = shipped_preset("vlp16");
  config.preprocess.deskew_check = false;
  const Drift tracked = run_sim(drive, config, true);
  const double tracked_rotation = max_frame_rotation_error_deg(drive, config);
  config.preprocess.redeskew = false;
  const Drift once = run_sim(drive, config, true);
  std::printf("  worst frame rotation error deskewed again: %.3f deg; once: end-point error %.3f m\n",
              tracked_rotation, once.end_error_m);
  // Measured: 0.26 m at the end of 176 m (0.15 %), 0.24 deg in the worst frame, worst frame
  // 0.26 m; deskewed once, 0.25 m at the end but 0.68 m in the worst frame. (Until session 41
  // the simulator cast a distorted sweep along the chord from its start pose to its end pose,
  // off the replay's middle pose by degrees in the spin's ramps: 0.73 m and 0.98 deg, and
  // deskewed once 130 m.)
  EXPECT_LT(tracked.end_error_m / tracked.path_m, 0.01);
  EXPECT_LT(tracked_rotation, 1.5);
}

// A hand-held walk: 1.4 m/s (0.14 m per sweep, under the check's 0.2 m) with the heading
// swaying +-31 deg/s at 0.5 Hz and the sensor pitching and rolling by up to 8 and 5 deg, as
// bench/unusual_motions.py's `handheld`. VLP-16; the street is laid along `walk_s` of the walk
// (a replay's world follows its path), the first `frames` are rendered.
test::RenderedDrive hand_held_walk_drive(bool motion_distortion, double walk_s = 40, std::size_t frames = 100) {
  PoseList lidar;
  double x = 0, y = 0, yaw = 0;
  for (int i = 0; i <= std::lround(100 * walk_s); ++i) {  // 100 Hz, every tenth pose kept
    const double t = 0.01 * i;
    if (i % 10 == 0) {
      const double pitch = 8 * M_PI / 180 * std::sin(2 * M_PI * 0.9 * t + 1.0);
      const double roll = 5 * M_PI / 180 * std::sin(2 * M_PI * 1.3 * t + 2.0);
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                    Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                    Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX())).toRotationMatrix();
      T.translation() = Eigen::Vector3d(x, y, 0);
      lidar.push_back(T);
    }
    const double speed = 1.4 * std::min(1.0, t / 1.0);  // starting from rest
    x += speed * std::cos(yaw) * 0.01;
    y += speed * std::sin(yaw) * 0.01;
    yaw += 10 * M_PI / 180 * M_PI * std::cos(M_PI * t) * 0.01;
  }
  return replayed_vlp16_drive(lidar, motion_distortion ? "hand_held_distorted" : "hand_held_compensated", 21,
                              motion_distortion, frames);
}

// The deskew check decides on a walk, where turning, not speed, distorts the sweeps: a point
// moves by its range times the sweep's angle. Until session 41 only the translation counted,
// the walk was never "in motion", and the check stayed undecided for 300 frames (a second
// odometry all along) and then kept deskew: a compensated VLP-16 walk with point times was
// deskewed again, 0.243 % t_err against 0.005 % (900 frames, docs/odometry.md "Session 41").
TEST(SimOdometry, DeskewCheckDecidesOnAHandHeldWalk) {
  const OdometryConfig preset = shipped_preset("vlp16");  // deskew on, check on
  OdometryConfig off = preset;
  off.preprocess.deskew = false;
  SettingCheck check;
  const test::RenderedDrive distorted = hand_held_walk_drive(true);
  run_sim(distorted, preset, /*use_rings=*/true, nullptr, &check);
  std::printf("  distorted walk: %s at frame %zu, median ratio %.3f\n", check.verdict.c_str(),
              check.decided_at_frame, check.residual_ratio);
  EXPECT_EQ(check.verdict, "distorted");
  EXPECT_LT(check.decided_at_frame, 60u);

  const test::RenderedDrive compensated = hand_held_walk_drive(false);
  const Drift checked = run_sim(compensated, preset, /*use_rings=*/true, nullptr, &check);
  std::printf("  compensated walk: %s at frame %zu, median ratio %.3f\n", check.verdict.c_str(),
              check.decided_at_frame, check.residual_ratio);
  EXPECT_EQ(check.verdict, "compensated");
  EXPECT_LT(check.decided_at_frame, 60u);
  // Switched, the track is the undeskewed odometry's from the first frame.
  const Drift raw = run_sim(compensated, off, /*use_rings=*/true);
  EXPECT_EQ(checked.end_error_m, raw.end_error_m);
}

// The same walk, 8 s of it: a replay's world follows its path, so this one holds one building
// along the street and the ground. Nothing matched says how far the sensor moves along the
// street (less than one match's worth of information there), so the second frame's coarse
// alignment, which starts from a guess of no motion, wandered by 0.24 m along it, and the
// weak direction's prior then carried that velocity on: frames off by up to 0.26 m, ATE 0.21 m
// (`scfloam run`, deskew off). It now keeps the guess where the matches say nothing: 0.05 m at
// most per frame, ATE 0.13 m (docs/odometry.md, "Session 41").
TEST(SimOdometry, FirstStepDoesNotWanderWhereNothingIsMatched) {
  OdometryConfig config = shipped_preset("vlp16");
  config.preprocess.deskew = false;  // compensated scans (the check cannot decide here: every frame is degenerate)
  const Drift d = run_sim(hand_held_walk_drive(false, 8, 0), config, /*use_rings=*/true);
  EXPECT_LT(d.first_frame_error_m, 0.05);
  EXPECT_LT(d.max_frame_error_m, 0.1);
}

// Raw sweeps whose source gives no point times (KITTI-style .bin files, older Velodyne drivers,
// exported PCD folders): the times come from the azimuth (features/sweep_times.hpp) and the
// drive tracks as with the driver's times; without them the scans stay distorted.
TEST(SimOdometry, ScansWithoutTimesAreDeskewedFromTheirAzimuth) {
  const OdometryConfig preset = shipped_preset("vlp16");  // deskew on, check on
  OdometryConfig forced = preset;
  forced.preprocess.deskew_check = false;
  OdometryConfig no_azimuth = forced;
  no_azimuth.preprocess.deskew_times_from_azimuth = false;
  const test::RenderedDrive& timed = distorted_vlp16_drive();
  test::RenderedDrive untimed = timed;
  for (Scan& scan : untimed.scans) {
    scan.has_time = false;
    for (LidarPoint& p : scan.points) p.time_s = 0;
  }
  // The times themselves: the simulator's, to a fraction of a degree of the sweep (a column is
  // 0.2 deg, 56 us).
  for (const std::size_t k : {0, 40, 99}) {
    std::vector<LidarPoint> points = untimed.scans[k].points;
    ASSERT_TRUE(assign_times_from_azimuth(points, timed.sweep_period_s).usable) << k;
    double worst = 0;
    for (std::size_t i = 0; i < points.size(); ++i)
      worst = std::max(worst, double(std::abs(points[i].time_s - timed.scans[k].points[i].time_s)));
    EXPECT_LT(worst, 3e-4) << k;
  }
  const Drift with_times = run_sim(timed, forced, true);
  const Drift from_azimuth = run_sim(untimed, forced, true);
  const Drift distorted = run_sim(untimed, no_azimuth, true);  // printed: what it was before
  // Measured: 0.305 m at the end and 12 mm per frame at most (the driver's times: 0.299 m,
  // 12 mm); left distorted 0.445 m and 23 mm.
  EXPECT_LT(from_azimuth.end_error_m, 1.5 * with_times.end_error_m + 0.02);
  EXPECT_LT(from_azimuth.max_frame_error_m, 1.5 * with_times.max_frame_error_m + 0.005);
  (void)distorted;

  // A scan out of firing order between two sweeps does not lose the seam: the next scan, whose
  // own seam is unclear (only the two lowest beams return near it), takes the first one's.
  Odometry odometry(forced);
  odometry.process(untimed.scans[0]);
  ASSERT_TRUE(odometry.azimuth_times().has_value());
  EXPECT_TRUE(odometry.azimuth_times()->usable);
  EXPECT_TRUE(odometry.azimuth_times()->clockwise);  // as the simulator turns
  Scan shuffled = untimed.scans[1];
  std::shuffle(shuffled.points.begin(), shuffled.points.end(), std::mt19937(2));
  EXPECT_FALSE(sweep_layout(shuffled.points).usable);
  odometry.process(shuffled);
  Scan unclear = untimed.scans[2];
  const double seam = odometry.azimuth_times()->seam_rad;
  unclear.points.erase(std::remove_if(unclear.points.begin(), unclear.points.end(),
                                      [&](const LidarPoint& p) {
                                        const double off = std::remainder(std::atan2(p.y, p.x) - seam, 2 * M_PI);
                                        return std::abs(off) < 10 * M_PI / 180 && p.z > -0.2 * std::hypot(p.x, p.y);
                                      }),
                       unclear.points.end());
  EXPECT_TRUE(sweep_layout(unclear.points).seam_unclear);
  odometry.process(unclear);
  EXPECT_TRUE(odometry.azimuth_times()->usable);
  EXPECT_TRUE(odometry.azimuth_times()->seam_from_earlier);
  // With the preset's check, the untimed scans prove distorted as the timed ones do.
  SettingCheck check;
  run_sim(untimed, preset, true, nullptr, &check);
  EXPECT_EQ(check.verdict, "distorted");
}

// Drivers stamp a sweep at its start (Ouster, Hesai), its end (Velodyne's ROS driver) or its
// middle (the simulator, KITTI), the point times counting from that stamp. The same sweeps
// stamped any of these ways must track alike, each at its own stamps. Until session 36 the
// odometry deskewed to the stamp: half a sweep from the points' own times, a small velocity
// error moved the whole scan, the next solve and deskew fed on it, and the error grew frame by
// frame (64 % t_err on bench/foreign_world.py's start-stamped sweeps); the deskew check,
// finding the deskewed solves worse, turned deskew off. Frame 0, solved before there is a
// velocity, is reported at its stamp too (the first step is checked).
TEST(SimOdometry, SweepsStampedAtTheirStartOrEndTrackLikeCentredOnes) {
  const OdometryConfig preset = shipped_preset("vlp16");  // deskew on, check on
  OdometryConfig forced = preset;
  forced.preprocess.deskew_check = false;
  const Drift centred = run_sim(distorted_vlp16_drive(), forced, true);
  for (const test::SweepStamp stamp : {test::SweepStamp::kStart, test::SweepStamp::kEnd}) {
    SCOPED_TRACE(stamp == test::SweepStamp::kStart ? "stamped at the sweep's start" : "at its end");
    const test::RenderedDrive drive = test::stamped_at(distorted_vlp16_drive(), stamp);
    const Drift d = run_sim(drive, forced, true);
    EXPECT_LT(d.first_frame_error_m, centred.first_frame_error_m + 0.02);
    // Reported at its stamp, a pose is the solve moved half a sweep at the last interval's
    // velocity: a few mm of its own (17 against 12 mm at the end of the sweep, measured).
    EXPECT_LT(d.max_frame_error_m, 2 * centred.max_frame_error_m);
    EXPECT_LT(d.end_error_m, 1.5 * centred.end_error_m + 0.02);
    SettingCheck check;
    run_sim(drive, preset, true, nullptr, &check);
    EXPECT_EQ(check.verdict, "distorted");
  }
}

// Frame 0 of a start-stamped sweep is solved at the sweep's middle before any velocity is
// known; frame 1 revises it: its features move to the stamp (the reported world's origin).
// The same sweep stamped at its middle gives frame 0's features there: seen from the start,
// the revised features must be those (frame 1's velocity decides the offset; without the
// revision they lie the ~0.3 m the sensor moved in half a sweep away).
TEST(SimOdometry, FrameZeroOfAStartStampedSweepIsRevisedToItsStamp) {
  OdometryConfig forced = shipped_preset("vlp16");
  forced.preprocess.deskew_check = false;
  const test::RenderedDrive& centred = distorted_vlp16_drive();
  const test::RenderedDrive start = test::stamped_at(centred, test::SweepStamp::kStart);
  Odometry at_middle(forced), at_start(forced);
  const OdometryResult middle0 = at_middle.process(centred.scans[0]);
  const OdometryResult start0 = at_start.process(start.scans[0]);
  EXPECT_TRUE(at_start.may_revise());
  EXPECT_FALSE(at_middle.may_revise());
  OdometryResult start1 = at_start.process(start.scans[1]);
  EXPECT_FALSE(at_start.may_revise());
  ASSERT_EQ(start1.revised.size(), 1u);
  const OdometryResult& revised0 = start1.revised[0];
  EXPECT_TRUE(revised0.T_world_lidar.isApprox(Eigen::Isometry3d::Identity()));
  ASSERT_EQ(revised0.planes.size(), middle0.planes.size());
  ASSERT_EQ(start0.planes.size(), middle0.planes.size());
  double revised_off = 0, unrevised_off = 0;
  for (std::size_t i = 0; i < middle0.planes.size(); ++i) {
    const Eigen::Vector3d want = centred.first_middle_from_start * middle0.planes[i].cast<double>();
    revised_off += (revised0.planes[i].cast<double>() - want).norm();
    unrevised_off += (start0.planes[i].cast<double>() - want).norm();
  }
  revised_off /= middle0.planes.size();
  unrevised_off /= middle0.planes.size();
  std::printf("  frame 0's plane features from the sweep's start: %.3f m off revised, %.3f m as solved\n",
              revised_off, unrevised_off);
  // Measured 0.038 against 0.320 m: the offset's translation is right to 3 mm, its rotation
  // (half of frame 1's, solved from two raw sweeps) to ~0.1 deg, 1 cm within 10 m, 4 cm beyond.
  EXPECT_LT(revised_off, 0.06);
  EXPECT_GT(unrevised_off, 0.2);
}

// An HDL-64E's beams look the same whether they read 0.2 deg low (KITTI's) or where its
// calibration says; KITTI's correction (the default) on the second kind tilts every scan and
// the odometry pitches steadily. The odometry runs without the correction alongside until the
// residuals say which fits (PreprocessConfig::elevation_check).
TEST(SimOdometry, ElevationCheckTellsKittiBeamsFromCalibratedOnes) {
  sim::SimConfig cfg = loops_drive("hdl64", 150, 29);
  const OdometryConfig checked;  // the defaults: KITTI's 0.22 deg, checked
  ASSERT_GT(checked.preprocess.elevation_correction_deg, 0);
  ASSERT_TRUE(checked.preprocess.elevation_check);
  OdometryConfig forced = checked, none = checked;
  forced.preprocess.elevation_check = false;
  none.preprocess.elevation_correction_deg = 0;

  // KITTI-like beams (the simulator's HDL-64E: 0.205 deg low): the correction stays, and the
  // corrected odometry is the one reported throughout.
  SettingCheck check;
  {
    const test::RenderedDrive drive = test::render_drive(cfg);
    const Drift kitti = run_sim(drive, checked, true, nullptr, nullptr, &check);
    EXPECT_EQ(check.verdict, "offset");
    EXPECT_LT(check.residual_ratio, 0.95);
    EXPECT_LT(check.decided_at_frame, 60u);
    EXPECT_EQ(kitti.end_error_m, run_sim(drive, forced, true).end_error_m);
  }  // one drive's scans in memory at a time (150 HDL-64E scans: ~0.4 GB)

  cfg.elevation_bias_deg = 0;  // calibrated beams (each still off by its own 0.02 deg, 1 sigma)
  const test::RenderedDrive calibrated_drive = test::render_drive(cfg);
  const Drift calibrated = run_sim(calibrated_drive, checked, true, nullptr, nullptr, &check);
  EXPECT_EQ(check.verdict, "no offset");
  EXPECT_GT(check.residual_ratio, 1.05);
  EXPECT_LT(check.decided_at_frame, 60u);
  const Drift calibrated_forced = run_sim(calibrated_drive, forced, true);
  const Drift calibrated_none = run_sim(calibrated_drive, none, true);
  // KITTI's correction on calibrated beams tilts the odometry steadily (measured, tilt drift
  // and end-point error: forced 0.40 deg, 0.38 m; none 0.035 deg, 0.022 m). The trial began at
  // frame 0 and the switch revised its frames: the checked track is the uncorrected one.
  EXPECT_GT(calibrated_forced.max_tilt_drift_deg, 3 * calibrated_none.max_tilt_drift_deg);
  EXPECT_EQ(calibrated.max_tilt_drift_deg, calibrated_none.max_tilt_drift_deg);
  EXPECT_EQ(calibrated.end_error_m, calibrated_none.end_error_m);
}

// A VLP-16's 2 deg rings leave the map's ground and walls as separate traces: five map
// neighbours of a plane point often lie on one trace, which any tilted plane fits, and the
// odometry then pitches a little every frame (docs/odometry.md, "Session 17"). The shipped
// preset (12 neighbours, 0.4 / 0.2 m map spacing) must hold the attitude on a drive with
// turns. Measured on this run (tilt drift, end-point error): the preset 0.12 deg, 0.02 %; with
// the preset's earlier 0.2 / 0.1 m spacing, 12 neighbours 0.22 deg, 0.06 %; 8: 0.29 deg,
// 0.05 %; F-LOAM's 5: 1.18 deg, 0.38 %.
TEST(SimOdometry, Vlp16PresetHoldsTheAttitudeThroughTurns) {
  const sim::SimConfig cfg = loops_drive("vlp16", 300, 13);
  OdometryConfig odo = shipped_preset("vlp16");
  odo.preprocess.deskew = false;  // the scans are not distorted
  const Drift d = run_sim(test::render_drive(cfg), odo, /*use_rings=*/true);
  EXPECT_GT(d.path_m, 200.0);
  EXPECT_LT(d.max_tilt_drift_deg, 0.5);
  EXPECT_LT(d.end_error_m / d.path_m, 0.002);
}

// A VLP-16 starting at a wide crossing (the 1200-frame loops world of seed 5): the buildings
// stand 25-50 m back, trees between. Beyond ~29 m its rings lie more than 1 m apart, so with a
// 1.0 m neighbour radius the far walls matched nothing; the lateral hold came from a few near
// planes, and the odometry slid sideways from frame 3 (the whole drive through `scfloam run`:
// 46 % t_err distorted, 0.26 % compensated). The preset's 1.25 m radius reaches across two rings
// there (docs/odometry.md, "Session 39").
// Measured over these 40 frames (end-point error, worst frame): 0.19 m, 0.011 m; with 1.0 m
// 9.1 m, 0.46 m (1.5 m: 0.20, 0.012; 2.0 m: 0.14, 0.008).
TEST(SimOdometry, Vlp16PresetHoldsItsLineWhereTheWallsStandFarBack) {
  const sim::SimConfig cfg = loops_drive("vlp16", 1200, 5);
  OdometryConfig odo = shipped_preset("vlp16");
  odo.preprocess.deskew = false;  // the scans are not distorted
  const test::RenderedDrive drive = test::render_drive(cfg, false, 40);
  const Drift d = run_sim(drive, odo, /*use_rings=*/true);
  EXPECT_GT(d.path_m, 25.0);
  EXPECT_LT(d.end_error_m, 0.5);
  EXPECT_LT(d.max_frame_error_m, 0.03);
}

// A distorted VLP-16 drive (the simulator's point times, traffic) that starts on an open square:
// for its first ten frames nothing pins the motion along the road (weakest translation
// eigenvalue 1-10), then for fifty only one or two far walls do (50-100, under the condition
// ratio). With the old prior weight (3) the deskewed odometry followed those few matches to
// a 4 % short step, the map's cross walls smeared and stopped matching, the deskew check then
// found the raw scans fitting better ("compensated" at frame 58 / 82) and the drive ended at
// 0.71 / 0.92 % t_err (`scfloam run`, 600 frames, as `.bin` / PCD with times; docs/odometry.md,
// "Session 40"). Measured over these 100 frames: weight 10 "distorted" at frame 27 (median
// ratio 0.885), end point 0.16 m over 60.6 m (5 and 30: the same within 6 mm); weight 3
// "compensated" at frame 74 (1.43), 0.34 m.
TEST(SimOdometry, Vlp16DeskewedStartOnAnOpenSquareKeepsItsSpeed) {
  sim::SimConfig cfg = loops_drive("vlp16", 600, 11);
  cfg.motion_distortion = true;
  const OdometryConfig preset = shipped_preset("vlp16");  // deskew on, check on
  ASSERT_TRUE(preset.preprocess.deskew && preset.preprocess.deskew_check);
  const test::RenderedDrive drive = test::render_drive(cfg, false, 100);
  SettingCheck check;
  const Drift d = run_sim(drive, preset, /*use_rings=*/true, nullptr, &check);
  std::printf("  deskew check: %s at frame %zu, median ratio %.3f; end point %.3f m over %.1f m\n",
              check.verdict.c_str(), check.decided_at_frame, check.residual_ratio, d.end_error_m, d.path_m);
  EXPECT_EQ(check.verdict, "distorted");
  EXPECT_GT(d.path_m, 55.0);
  EXPECT_LT(d.end_error_m, 0.25);
}

// A sensor none of the built-in ring tables describes (VLP-32C: 1/3 deg beams around the
// horizon, 9.4 deg apart at the bottom), without a ring field, in firing order, run with the
// nearest preset (HDL-32E): its table puts two or three beams into one ring, so the odometry
// learns the beams from the first scan instead (features/beam_layout.hpp).
TEST(SimOdometry, UnknownBeamLayoutIsLearnedFromTheScans) {
  const sim::SimConfig cfg = loops_drive("vlp32c", 150, 17);
  OdometryConfig odo = shipped_preset("hdl32");
  odo.preprocess.deskew = false;  // the scans are not distorted
  RingLayoutInfo rings;
  const Drift d = run_sim(test::render_drive(cfg, /*firing_order=*/true), odo, /*use_rings=*/false, &rings);
  EXPECT_EQ(rings.source, "learned");
  EXPECT_EQ(rings.beams, 32);
  EXPECT_NEAR(rings.highest_deg, 15.0, 0.02);
  EXPECT_NEAR(rings.lowest_deg, -25.0, 0.02);
  EXPECT_GT(d.path_m, 80.0);
  EXPECT_LT(d.end_error_m / d.path_m, 0.005);
  EXPECT_LT(d.max_tilt_drift_deg, 0.3);
}

}  // namespace
}  // namespace scfloam

namespace scfloam {
namespace {

// A 64-beam sensor whose beams all point 0.205 deg higher than its table (KITTI's error, the
// simulator's HDL-64E default), run with no correction configured: an online estimate has to
// find the offset on its own, and the attitude must then drift less than without it.
struct ElevationRun {
  double estimate_deg = 0, tilt_fixed_deg = 0, tilt_online_deg = 0;
};

ElevationRun run_unknown_offset(const OdometryConfig& online, std::size_t frames, std::size_t from) {
  sim::SimConfig cfg;
  cfg.route = "loops";
  cfg.frames = frames;
  cfg.seed = 2;
  const sim::SensorModel sensor = sim::sensor_for(cfg);
  const sim::Scenario sc = sim::build_scenario(cfg);
  const sim::BeamCalibration calib = sim::draw_beam_calibration(sensor, cfg.seed);
  OdometryConfig fixed;
  fixed.preprocess.elevation_correction_deg = 0;
  Odometry odometry_fixed(fixed), odometry_online(online);
  Eigen::Isometry3d gt0, est0_fixed, est0_online;
  ElevationRun out;
  const auto tilt_deg = [](const Eigen::Isometry3d& gt, const Eigen::Isometry3d& est) {
    const Eigen::Vector3d up_gt = gt.linear().transpose() * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d up_est = est.linear().transpose() * Eigen::Vector3d::UnitZ();
    return std::atan2(up_gt.cross(up_est).norm(), up_gt.dot(up_est)) * 180 / M_PI;
  };
  for (std::size_t k = 0; k < sc.frames; ++k) {
    const Scan scan = sim::render_frame(sc, sensor, calib, cfg, k);
    const Eigen::Isometry3d est_fixed = odometry_fixed.process(scan).T_world_lidar;
    const OdometryResult r = odometry_online.process(scan);
    out.estimate_deg = r.elevation_correction_deg;
    // The attitude is compared after the estimate's convergence, from frame `from` on.
    if (k == from) {
      gt0 = sim::sensor_pose_at(sc, sensor, sc.frame_time(k));
      est0_fixed = est_fixed;
      est0_online = r.T_world_lidar;
    } else if (k > from) {
      const Eigen::Isometry3d gt = gt0.inverse() * sim::sensor_pose_at(sc, sensor, sc.frame_time(k));
      out.tilt_fixed_deg = std::max(out.tilt_fixed_deg, tilt_deg(gt, est0_fixed.inverse() * est_fixed));
      out.tilt_online_deg = std::max(out.tilt_online_deg, tilt_deg(gt, est0_online.inverse() * r.T_world_lidar));
    }
  }
  std::printf("  estimated offset %.3f deg (truth 0.205 + the beams' own errors); tilt drift from "
              "frame %zu: fixed 0 %.3f deg, online %.3f deg\n",
              out.estimate_deg, from, out.tilt_fixed_deg, out.tilt_online_deg);
  return out;
}

TEST(SimOdometry, OnlineElevationEstimateFindsAnUnknownOffset) {
  OdometryConfig online;
  online.preprocess.elevation_correction_deg = 0;
  online.preprocess.online_elevation_calibration = true;
  // The plane-match estimate converges over the map's turnover, ~150 frames.
  const ElevationRun r = run_unknown_offset(online, 250, 150);
  EXPECT_NEAR(r.estimate_deg, 0.205, 0.07);
  EXPECT_LT(r.tilt_online_deg, 0.5 * r.tilt_fixed_deg);
}

TEST(SimOdometry, GroundElevationEstimateFindsAnUnknownOffset) {
  OdometryConfig online;
  online.preprocess.elevation_correction_deg = 0;
  online.preprocess.ground_elevation_calibration = true;
  // The road-pair estimate is in use from its 10th pair, ~20 frames in.
  const ElevationRun r = run_unknown_offset(online, 150, 50);
  EXPECT_NEAR(r.estimate_deg, 0.205, 0.03);
  EXPECT_LT(r.tilt_online_deg, 0.3 * r.tilt_fixed_deg);
}

}  // namespace
}  // namespace scfloam
