// Routes: physical driving (speed, acceleration, yaw rate), real revisits on the loops
// route, and a replayed KITTI trajectory that is followed exactly with a clear road.
#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "scfloam/io/kitti.hpp"
#include "scfloam/io/trajectory.hpp"
#include "scfloam/se3.hpp"
#include "scfloam/sim/scenario.hpp"
#include "test_paths.hpp"

namespace scfloam::sim {
namespace {

double yaw_of(const Pose& T) { return std::atan2(T.linear()(1, 0), T.linear()(0, 0)); }
double wrap(double a) { return std::atan2(std::sin(a), std::cos(a)); }

struct Revisits {
  double same_dir_longest_loop_m = 0;  // path length between the two passes
  bool opposite = false;
};

Revisits find_revisits(const Scenario& sc) {
  std::vector<Pose> poses;
  std::vector<double> dist{0};
  for (std::size_t k = 0; k < sc.frames; ++k) {
    poses.push_back(sc.frame_pose(k));
    if (k > 0) dist.push_back(dist.back() + (poses[k].translation() - poses[k - 1].translation()).norm());
  }
  Revisits r;
  for (std::size_t j = 0; j < poses.size(); j += 2)
    for (std::size_t i = 0; i < j; i += 2) {
      if (dist[j] - dist[i] < 150) continue;
      const double d = (poses[i].translation() - poses[j].translation()).head<2>().norm();
      const double dyaw = std::abs(wrap(yaw_of(poses[i]) - yaw_of(poses[j])));
      if (d < 3.0 && dyaw < 0.5) r.same_dir_longest_loop_m = std::max(r.same_dir_longest_loop_m, dist[j] - dist[i]);
      if (d < 8.0 && dyaw > M_PI - 0.5) r.opposite = true;
    }
  return r;
}

TEST(LoopsRoute, DrivesLikeACar) {
  const Scenario sc = make_loops_scenario(5, 1000);
  ASSERT_EQ(sc.frames, 1000u);
  const double dt = sc.frame_period_s;
  double prev_speed = -1, prev_yaw_rate = 0;
  for (std::size_t k = 1; k + 1 < sc.frames; ++k) {
    const Pose a = sc.frame_pose(k - 1), b = sc.frame_pose(k);
    const double speed = (b.translation() - a.translation()).norm() / dt;
    EXPECT_GE(speed, 4.9) << k;
    EXPECT_LE(speed, 12.1) << k;
    if (prev_speed > 0) {
      EXPECT_LE(std::abs(speed - prev_speed) / dt, 2.0) << k;  // m/s^2
    }
    const double yaw_rate = wrap(yaw_of(b) - yaw_of(a)) / dt;
    EXPECT_LE(std::abs(yaw_rate), 0.7) << k;
    if (k > 1) {
      EXPECT_LE(std::abs(yaw_rate - prev_yaw_rate) / dt, 1.5) << k;  // rad/s^2
    }
    prev_speed = speed;
    prev_yaw_rate = yaw_rate;
    // Roll and pitch stay small (terrain of a few % plus suspension).
    const Eigen::Vector3d up = b.linear().col(2);
    EXPECT_GT(up.z(), std::cos(5 * M_PI / 180)) << k;
    // The sensor rides at its mount height over the road.
    EXPECT_NEAR(b.translation().z() - sc.world.terrain_m.sample(b.translation().x(), b.translation().y()), 1.73, 0.05);
    EXPECT_TRUE(sc.world.on_road(b.translation().x(), b.translation().y())) << k;
  }
}

TEST(LoopsRoute, ThousandFramesRevisitBothWays) {
  const Scenario sc = make_loops_scenario(1, 1000);
  const Revisits r = find_revisits(sc);
  EXPECT_GT(r.same_dir_longest_loop_m, 250.0);
  EXPECT_TRUE(r.opposite);
}

TEST(LoopsRoute, LongRoutesCloseALoopLongerThanOneKilometre) {
  const Scenario sc = make_loops_scenario(2, 3500);
  const Revisits r = find_revisits(sc);
  EXPECT_GT(r.same_dir_longest_loop_m, 1000.0);
  EXPECT_TRUE(r.opposite);
}

bool inside(const Primitive& p, const Eigen::Vector3d& q) {
  const double dx = q.x() - p.cx, dy = q.y() - p.cy;
  switch (p.shape) {
    case Primitive::Shape::box: {
      const double lx = p.cos_yaw * dx + p.sin_yaw * dy, ly = -p.sin_yaw * dx + p.cos_yaw * dy;
      return std::abs(lx) <= p.hx && std::abs(ly) <= p.hy && q.z() >= p.z0 && q.z() <= p.z1;
    }
    case Primitive::Shape::cylinder:
      return dx * dx + dy * dy <= p.hx * p.hx && q.z() >= p.z0 && q.z() <= p.z1;
    case Primitive::Shape::ellipsoid: {
      const double dz = (q.z() - p.z0) * p.hx / p.z1;
      return dx * dx + dy * dy + dz * dz <= p.hx * p.hx;
    }
  }
  return false;
}

TEST(ReplayRoute, FollowsKittiPosesWithAClearRoad) {
  SCFLOAM_SHARED_DATA_OR_SKIP(poses_file, "kitti/ground-truth/poses/05.txt");
  const PoseList lidar = camera_to_lidar_poses(read_kitti_poses(poses_file), kitti_default_Tr());
  const Scenario sc = make_replay_scenario(lidar, 4, 300);
  ASSERT_EQ(sc.frames, 300u);
  for (std::size_t k = 0; k < sc.frames; ++k) {
    // x, y and rotation are the file's; z rides 1.73 m over the fitted terrain.
    EXPECT_LT((sc.frame_pose(k).translation() - lidar[k].translation()).head<2>().norm(), 1e-9) << k;
    const Eigen::Vector3d c = sc.frame_pose(k).translation();
    EXPECT_NEAR(c.z() - sc.world.terrain_m.sample(c.x(), c.y()), 1.73, 1e-6) << k;
    EXPECT_NEAR(c.z(), lidar[k].translation().z(), 1.0) << k;  // 05 is consistent to ~0.6 m
    EXPECT_LT((sc.frame_pose(k).linear() - lidar[k].linear()).norm(), 1e-6) << k;  // KITTI's R is orthonormal to ~1e-7
  }
  // The whole path (not only the replayed frames) runs on the road, clear of every object
  // the car's body could touch (a 2 x 1 m footprint, 0.3-2.0 m above the ground).
  std::size_t checked = 0;
  for (std::size_t k = 0; k < lidar.size(); k += 25, ++checked) {
    const Eigen::Vector3d c = sc.trajectory.T_world_lidar[k].translation();
    ASSERT_TRUE(sc.world.on_road(c.x(), c.y())) << k;
    const double g = sc.world.ground_height(c.x(), c.y());
    for (const auto& p : sc.world.primitives)
      for (double dz : {0.3, 1.0, 2.0})
        for (double a : {-2.0, 0.0, 2.0})
          for (double b : {-1.0, 1.0}) {
            const Eigen::Vector3d q = Eigen::Vector3d(c.x(), c.y(), g + dz) + lidar[k].linear().col(0) * a + lidar[k].linear().col(1) * b;
            ASSERT_FALSE(inside(p, q)) << "pose " << k << " collides with a " << surface_kind_name(p.kind);
          }
  }
  EXPECT_GT(checked, 100u);
  EXPECT_GT(sc.stats.buildings, 150u);  // 2.2 km of street, both sides, plus side streets
}

}  // namespace
}  // namespace scfloam::sim

namespace scfloam::sim {
namespace {

// A trajectory sampled once per frame (a replay) and joined by a cubic passes through its
// samples and turns and pitches without a kink at them: a sweep around a sample moves along
// a curve, as a sensor does, not along two straight pieces.
TEST(SampledTrajectory, ASmoothReplayPassesThroughItsPosesWithoutKinks) {
  SampledTrajectory traj;
  traj.dt_s = 0.1;
  for (int k = 0; k < 8; ++k) {  // pitching at 1 Hz by 8 deg while walking and turning
    const double t = 0.1 * k;
    Pose T = Pose::Identity();
    T.linear() = (Eigen::AngleAxisd(0.5 * t, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(0.14 * std::sin(2 * M_PI * t), Eigen::Vector3d::UnitY())).toRotationMatrix();
    T.translation() = Eigen::Vector3d(1.4 * t, 0.2 * t * t, 0);
    traj.T_world_lidar.push_back(T);
  }
  // The rotation rate (rad/s) just before and just after time t.
  const auto rates = [&](double t) {
    const double h = 1e-4;
    const Eigen::Vector3d before = so3_log(traj.at(t - h).linear().transpose() * traj.at(t).linear()) / h;
    const Eigen::Vector3d after = so3_log(traj.at(t).linear().transpose() * traj.at(t + h).linear()) / h;
    return std::pair{before, after};
  };
  for (const bool smooth : {false, true}) {
    traj.smooth = smooth;
    for (int k = 0; k < 8; ++k) {
      EXPECT_LT((traj.at(0.1 * k).translation() - traj.T_world_lidar[k].translation()).norm(), 1e-9);
      EXPECT_LT(so3_log(traj.at(0.1 * k).linear().transpose() * traj.T_world_lidar[k].linear()).norm(), 1e-9);
    }
    const auto [before, after] = rates(0.3);
    // Straight pieces: the pitch rate jumps by ~0.5 rad/s at the sample; the cubic: by the
    // finite difference's own error.
    if (smooth) EXPECT_LT((after - before).norm(), 0.01) << "smooth";
    else EXPECT_GT((after - before).norm(), 0.3) << "straight pieces";
  }
}

TEST(LoopsRoute, CarBodyStaysOnTheRoadClearOfObjects) {
  for (std::uint64_t seed : {1, 2, 7}) {
    const Scenario sc = make_loops_scenario(seed, 1000);
    for (std::size_t k = 0; k < sc.frames; k += 5) {
      const Pose T = sc.frame_pose(k);
      const Eigen::Vector3d c = T.translation();
      const double g = sc.world.terrain_m.sample(c.x(), c.y());
      for (double a : {-2.2, 0.0, 2.2})
        for (double b : {-0.95, 0.95}) {
          const Eigen::Vector3d q = c + T.linear().col(0) * a + T.linear().col(1) * b;
          ASSERT_LT(sc.world.road_edge_distance.sample(q.x(), q.y()), -0.1) << "seed " << seed << " frame " << k;
          for (double dz : {0.3, 1.0, 1.9})
            for (const auto& p : sc.world.primitives)
              ASSERT_FALSE(inside(p, Eigen::Vector3d(q.x(), q.y(), g + dz)))
                  << "seed " << seed << " frame " << k << " hits a " << surface_kind_name(p.kind);
        }
    }
  }
}

}  // namespace
}  // namespace scfloam::sim
