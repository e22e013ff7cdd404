// Loop registration on simulated scans with known ground truth: the feature method and the ICP
// baseline recover a known offset to a submap; a candidate from another place is rejected.
#include <gtest/gtest.h>
#include <dlfcn.h>

#include <thread>

#include "scfloam/config.hpp"
#include "scfloam/loop/loop_registration.hpp"
#include "scfloam/odometry/odometry.hpp"
#include "scfloam/registration/voxel_filter.hpp"
#include "scfloam/se3.hpp"
#include "scfloam/sim/scan.hpp"
#include "scfloam/sim/scenario.hpp"
#include "scfloam/sim/sensor.hpp"

using namespace scfloam;

namespace {

struct SimKeyframe {
  Eigen::Isometry3d T_world_lidar;
  FeatureCloud edges, planes, raw;
};

class LoopRegistrationTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scenario_ = new sim::Scenario(sim::make_loops_scenario(21, 400));
    sensor_ = new sim::SensorModel(sim::sensor_preset("hdl64"));
    calib_ = new sim::BeamCalibration(sim::draw_beam_calibration(*sensor_, 21));
  }
  static void TearDownTestSuite() {
    delete scenario_;
    delete sensor_;
    delete calib_;
  }

  // A keyframe seen from `T_world_lidar`: features as the odometry extracts them.
  static SimKeyframe make_keyframe(const Eigen::Isometry3d& T_world_lidar, std::uint64_t id) {
    sim::SweepPoses poses;
    poses.T_world_lidar = T_world_lidar;
    const Scan scan = sim::render_scan(scenario_->world, *sensor_, *calib_, poses, 21, id);
    Odometry odometry(OdometryConfig{});
    const OdometryResult r = odometry.process(scan);
    SimKeyframe kf{T_world_lidar, r.edges, r.planes, {}};
    FeatureCloud raw;
    for (const auto& p : scan.points) raw.emplace_back(p.x, p.y, p.z);
    kf.raw = voxel_downsample(raw, 0.4);
    return kf;
  }

  // Keyframes every 3rd frame around `center_frame`, at their true poses.
  static std::vector<SimKeyframe> make_submap(std::size_t center_frame, int neighbours) {
    std::vector<SimKeyframe> out;
    for (int i = -neighbours; i <= neighbours; ++i) {
      const std::size_t frame = center_frame + 3 * i;
      out.push_back(make_keyframe(scenario_->frame_pose(frame), 1000 + frame));
    }
    return out;
  }

  // The revisit of frame 150 (submap of +-6 keyframes, the loop keyframe at index 6): a pose
  // the car never had, 1.2 m aside and turned 5 degrees, its estimate off by `drift`.
  struct Revisit {
    std::vector<SimKeyframe> submap;
    SimKeyframe current;
    Eigen::Isometry3d truth;  // T_loop_current
  };
  static Revisit make_revisit(const Eigen::Isometry3d& drift) {
    Revisit v;
    v.submap = make_submap(150, 6);
    const Eigen::Isometry3d T_world_current = scenario_->frame_pose(150) * offset(0.4, 1.2, 5);
    v.current = make_keyframe(T_world_current, 7);
    v.current.T_world_lidar = T_world_current * drift;
    v.truth = v.submap[6].T_world_lidar.inverse() * T_world_current;
    return v;
  }

  static Eigen::Isometry3d offset(double dx, double dy, double yaw_deg) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = so3_exp(Eigen::Vector3d(0, 0, yaw_deg * M_PI / 180));
    T.translation() = Eigen::Vector3d(dx, dy, 0);
    return T;
  }

  static std::vector<KeyframeView> views(const std::vector<SimKeyframe>& kfs) {
    std::vector<KeyframeView> out;
    for (const auto& kf : kfs) out.push_back({kf.T_world_lidar, &kf.edges, &kf.planes, &kf.raw});
    return out;
  }

  static sim::Scenario* scenario_;
  static sim::SensorModel* sensor_;
  static sim::BeamCalibration* calib_;
};

sim::Scenario* LoopRegistrationTest::scenario_ = nullptr;
sim::SensorModel* LoopRegistrationTest::sensor_ = nullptr;
sim::BeamCalibration* LoopRegistrationTest::calib_ = nullptr;

}  // namespace

TEST_F(LoopRegistrationTest, FeaturesRecoverAKnownOffset) {
  // Drift: the pose estimate is off by 0.8 m and 3 degrees.
  const Revisit v = make_revisit(offset(0.6, -0.5, 3));
  const LoopMatch match = register_loop_features(
      {v.current.T_world_lidar, &v.current.edges, &v.current.planes, &v.current.raw}, views(v.submap), 6,
      0.0, LoopRegistrationConfig{}, RegistrationConfig{}, LocalMapConfig{});
  ASSERT_TRUE(match.accepted) << match.reason;
  const Eigen::Isometry3d error = v.truth.inverse() * match.T_loop_current;
  EXPECT_LT(error.translation().norm(), 0.05);
  EXPECT_LT(rotation_angle_rad(error.linear()) * 180 / M_PI, 0.2);
  EXPECT_GT(match.inlier_fraction, 0.6);
}

TEST_F(LoopRegistrationTest, CheckCountsPlanesUnderItsOwnFlatnessTest) {
  // The solve refuses rough patches (registration.plane_max_dist_m); the acceptance check
  // counts matches under its own test, so it moves the verdict's count, never the pose.
  const Revisit v = make_revisit(offset(0.3, -0.2, 1));
  auto match_with_check = [&](double check_m) {
    LoopRegistrationConfig config;
    config.check_plane_max_dist_m = check_m;
    return register_loop_features(
        {v.current.T_world_lidar, &v.current.edges, &v.current.planes, &v.current.raw}, views(v.submap), 6,
        0.0, config, RegistrationConfig{}, LocalMapConfig{});
  };
  const double solve_m = RegistrationConfig{}.plane_max_dist_m;
  ASSERT_LT(solve_m, 0.2);
  const LoopMatch loose = match_with_check(0.2), same = match_with_check(solve_m),
                  strict = match_with_check(0.03);
  EXPECT_TRUE(loose.T_loop_current.isApprox(same.T_loop_current, 1e-12));
  EXPECT_TRUE(loose.T_loop_current.isApprox(strict.T_loop_current, 1e-12));
  // The simulated street has rough patches (tree crowns): a looser test counts more of them.
  EXPECT_GT(loose.inlier_fraction, same.inlier_fraction);
  EXPECT_GT(same.inlier_fraction, strict.inlier_fraction);
}

TEST_F(LoopRegistrationTest, ScanContextYawRescuesAWrongHeadingGuess) {
  const std::size_t loop_frame = 150;
  const auto submap = make_submap(loop_frame, 6);
  // Revisit driven the other way: 180 degrees turned; the pose estimate has drifted 4 m and
  // 20 degrees, too far for the first guess, so Scan Context's yaw must carry it.
  const Eigen::Isometry3d T_world_current = scenario_->frame_pose(loop_frame) * offset(0.5, 0.3, 180);
  SimKeyframe current = make_keyframe(T_world_current, 8);
  current.T_world_lidar = T_world_current * offset(3.0, 2.5, 20);
  const Eigen::Isometry3d truth = submap[6].T_world_lidar.inverse() * T_world_current;
  const double sc_yaw = M_PI - 2 * M_PI / 60;  // off by one 6-degree sector
  const LoopMatch match = register_loop_features(
      {current.T_world_lidar, &current.edges, &current.planes, &current.raw}, views(submap), 6,
      sc_yaw, LoopRegistrationConfig{}, RegistrationConfig{}, LocalMapConfig{});
  ASSERT_TRUE(match.accepted) << match.reason;
  const Eigen::Isometry3d error = truth.inverse() * match.T_loop_current;
  EXPECT_LT(error.translation().norm(), 0.05);
  EXPECT_LT(rotation_angle_rad(error.linear()) * 180 / M_PI, 0.2);
}

TEST_F(LoopRegistrationTest, FineFirstGivesTheCoarseToFineAnswerFromAGoodGuess) {
  // After a revisit's first loop the graph is closed: the pose guess is off by centimetres.
  const std::size_t loop_frame = 150;
  const auto submap = make_submap(loop_frame, 6);
  const Eigen::Isometry3d T_world_current = scenario_->frame_pose(loop_frame) * offset(0.4, 1.2, 5);
  SimKeyframe current = make_keyframe(T_world_current, 10);
  current.T_world_lidar = T_world_current * offset(0.03, -0.02, 0.1);
  const Eigen::Isometry3d truth = submap[6].T_world_lidar.inverse() * T_world_current;
  LoopRegistrationConfig fine_first, coarse_to_fine;
  fine_first.fine_first = true;
  coarse_to_fine.fine_first = false;
  const KeyframeView view{current.T_world_lidar, &current.edges, &current.planes, &current.raw};
  const LoopMatch a = register_loop_features(view, views(submap), 6, 0.0, fine_first,
                                             RegistrationConfig{}, LocalMapConfig{});
  const LoopMatch b = register_loop_features(view, views(submap), 6, 0.0, coarse_to_fine,
                                             RegistrationConfig{}, LocalMapConfig{});
  ASSERT_TRUE(a.accepted) << a.reason;
  ASSERT_TRUE(b.accepted) << b.reason;
  for (const LoopMatch* m : {&a, &b}) {
    const Eigen::Isometry3d error = truth.inverse() * m->T_loop_current;
    EXPECT_LT(error.translation().norm(), 0.05);
    EXPECT_LT(rotation_angle_rad(error.linear()) * 180 / M_PI, 0.2);
  }
  const Eigen::Isometry3d between = a.T_loop_current.inverse() * b.T_loop_current;
  EXPECT_LT(between.translation().norm(), 0.01);
}

TEST_F(LoopRegistrationTest, IcpBaselineRecoversAKnownOffset) {
  const std::size_t loop_frame = 150;
  const auto submap = make_submap(loop_frame, 4);
  const Eigen::Isometry3d T_world_current = scenario_->frame_pose(loop_frame) * offset(0.4, 1.2, 5);
  SimKeyframe current = make_keyframe(T_world_current, 9);
  current.T_world_lidar = T_world_current * offset(0.6, -0.5, 3);
  const Eigen::Isometry3d truth = submap[4].T_world_lidar.inverse() * T_world_current;
  const LoopMatch match =
      register_loop_icp({current.T_world_lidar, &current.edges, &current.planes, &current.raw},
                        views(submap), 4, 0.0, LoopRegistrationConfig{});
  ASSERT_TRUE(match.accepted) << match.reason;
  const Eigen::Isometry3d error = truth.inverse() * match.T_loop_current;
  EXPECT_LT(error.translation().norm(), 0.15);
  EXPECT_LT(rotation_angle_rad(error.linear()) * 180 / M_PI, 0.5);
}

// Deterministic runs: with the guard, ICP from this thread runs on one OpenMP thread and repeats
// itself bit for bit; other threads keep their count, and this one gets its own back after.
TEST_F(LoopRegistrationTest, IcpRepeatsItselfExactlyUnderTheDeterministicGuard) {
  using MaxThreads = int (*)();
  const auto max_threads = reinterpret_cast<MaxThreads>(::dlsym(RTLD_DEFAULT, "omp_get_max_threads"));
  ASSERT_NE(max_threads, nullptr) << "Open3D's OpenMP runtime (libgomp) is not loaded";
  const int before = max_threads();
  const std::size_t loop_frame = 150;
  const auto submap = make_submap(loop_frame, 4);
  const Eigen::Isometry3d T_world_current = scenario_->frame_pose(loop_frame) * offset(0.4, 1.2, 5);
  SimKeyframe current = make_keyframe(T_world_current, 9);
  current.T_world_lidar = T_world_current * offset(0.6, -0.5, 3);
  std::vector<LoopMatch> matches;
  {
    const IcpOnThisThreadRepeatable guard;
    EXPECT_EQ(max_threads(), 1);
    int other_thread = 0;
    std::thread([&] { other_thread = max_threads(); }).join();
    EXPECT_EQ(other_thread, before);
    for (int i = 0; i < 3; ++i)
      matches.push_back(register_loop_icp({current.T_world_lidar, &current.edges, &current.planes, &current.raw},
                                          views(submap), 4, 0.0, LoopRegistrationConfig{}));
  }
  EXPECT_EQ(max_threads(), before);
  ASSERT_TRUE(matches[0].accepted) << matches[0].reason;
  for (int i = 1; i < 3; ++i) {
    EXPECT_TRUE(matches[i].T_loop_current.matrix() == matches[0].T_loop_current.matrix()) << "run " << i;
    EXPECT_EQ(matches[i].residual_m, matches[0].residual_m) << "run " << i;
  }
}

TEST_F(LoopRegistrationTest, CandidateFromAnotherPlaceIsRejected) {
  const std::size_t loop_frame = 150;
  const auto submap = make_submap(loop_frame, 6);
  // A keyframe far along the route, claimed to be at the loop keyframe.
  const Eigen::Isometry3d T_world_elsewhere = scenario_->frame_pose(330);
  ASSERT_GT((T_world_elsewhere.translation() - submap[6].T_world_lidar.translation()).norm(), 60.0);
  SimKeyframe current = make_keyframe(T_world_elsewhere, 10);
  current.T_world_lidar = submap[6].T_world_lidar;  // where a false Scan Context match puts it
  const LoopMatch match = register_loop_features(
      {current.T_world_lidar, &current.edges, &current.planes, &current.raw}, views(submap), 6, 0.0,
      LoopRegistrationConfig{}, RegistrationConfig{}, LocalMapConfig{});
  EXPECT_FALSE(match.accepted) << "inliers " << match.inlier_fraction << ", residual "
                               << match.residual_m;
  EXPECT_FALSE(match.reason.empty());
}
