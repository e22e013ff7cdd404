// Moving objects: they move as their velocities say, leaders keep the ego's pace, nobody
// drives through the ego car, a city has a few cars nearby, the renderer shows them, and a
// scene without traffic renders exactly as before.
#include <gtest/gtest.h>

#include "scfloam/sim/scan.hpp"
#include "scfloam/sim/simulate.hpp"

namespace scfloam::sim {
namespace {
using Vec2 = Eigen::Vector2d;

class TrafficTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SimConfig cfg;
    cfg.seed = 5;
    cfg.frames = 600;
    cfg.route = "loops";
    scenario_ = new Scenario(build_scenario(cfg));
    traffic_ = new Traffic(scenario_->trajectory, scenario_->world, TrafficConfig{}, cfg.seed);
  }
  static void TearDownTestSuite() {
    delete traffic_;
    delete scenario_;
  }
  static Scenario* scenario_;
  static Traffic* traffic_;
};
Scenario* TrafficTest::scenario_ = nullptr;
Traffic* TrafficTest::traffic_ = nullptr;

TEST_F(TrafficTest, EveryKindIsPlanned) {
  int count[4] = {0, 0, 0, 0};
  for (const Mover& m : traffic_->movers()) ++count[static_cast<int>(m.kind)];
  EXPECT_GT(count[0], 10);  // 60 s at 20 oncoming cars per minute
  EXPECT_GT(count[1], 0);
  EXPECT_GT(count[2], 0);
  EXPECT_GT(count[3], 2);
}

TEST_F(TrafficTest, OncomingAndPedestriansMoveAtTheirSpeed) {
  int checked = 0;
  for (const Mover& m : traffic_->movers()) {
    if (m.kind != Mover::Kind::oncoming && m.kind != Mover::Kind::pedestrian) continue;
    const double t0 = 0.5 * (m.t_on_s + m.t_off_s), dt = 0.5;
    Vec2 a, b, ha, hb;
    if (!traffic_->state(m, t0, &a, &ha) || !traffic_->state(m, t0 + dt, &b, &hb)) continue;
    // On straight streets the distance is |v| dt (in turns the lateral offset from the ego
    // path scales it by 1 +- offset / radius).
    if (ha.dot(hb) < std::cos(0.01)) continue;
    const double expected = std::abs(m.speed_mps) * dt;
    EXPECT_NEAR((b - a).norm(), expected, 0.03 * expected + 0.01);
    // Moving where it faces.
    EXPECT_GT((b - a).normalized().dot(ha), 0.8);
    ++checked;
  }
  EXPECT_GT(checked, 10);
}

TEST_F(TrafficTest, LeadersKeepTheEgoPaceAndNobodyTouchesTheEgoCar) {
  double worst_clearance = 1e9;
  int leader_samples = 0;
  for (std::size_t k = 0; k + 10 < scenario_->frames; k += 5) {
    const double t = k * scenario_->frame_period_s;
    const Vec2 ego = scenario_->frame_pose(k).translation().head<2>();
    const Vec2 ego_next = scenario_->frame_pose(k + 10).translation().head<2>();
    for (const Mover& m : traffic_->movers()) {
      Vec2 c, h, c_next, h_next;
      if (!traffic_->state(m, t, &c, &h)) continue;
      // Distance from the ego lidar (car center) to the mover's footprint rectangle.
      const Vec2 rel = ego - c;
      const double along = std::max(0.0, std::abs(rel.dot(h)) - m.half_len_m);
      const double across = std::max(0.0, std::abs(rel.dot(Vec2(-h.y(), h.x()))) - m.half_width_m);
      worst_clearance = std::min(worst_clearance, std::hypot(along, across));
      // Away from the entry/exit ramps a leader moves like the ego (within its wobble).
      if (m.kind == Mover::Kind::leader && t > m.t_on_s + 12 && t + 1 < m.t_off_s - 12 &&
          traffic_->state(m, t + 1, &c_next, &h_next)) {
        const double ego_speed = (ego_next - ego).norm(), leader_speed = (c_next - c).norm();
        EXPECT_NEAR(leader_speed, ego_speed, 0.35 * ego_speed + m.wobble_m * m.wobble_rad_s + 0.3);
        ++leader_samples;
      }
    }
  }
  EXPECT_GT(worst_clearance, 1.8);  // the ego car is ~0.9 m wide each side of its center
  EXPECT_GT(leader_samples, 5);
}

TEST_F(TrafficTest, ACityHasAFewCarsNearby) {
  double total = 0;
  std::size_t frames_with_any = 0, n = 0;
  for (std::size_t k = 0; k < scenario_->frames; k += 10, ++n) {
    const double t = k * scenario_->frame_period_s;
    const std::size_t near = traffic_->count_near(t, scenario_->frame_pose(k).translation().head<2>(), 50);
    total += near;
    frames_with_any += near > 0;
  }
  EXPECT_GT(total / n, 1.0);
  EXPECT_LT(total / n, 8.0);
  EXPECT_GT(static_cast<double>(frames_with_any) / n, 0.6);
}

TEST_F(TrafficTest, SameSeedSamePlan) {
  const Traffic again(scenario_->trajectory, scenario_->world, TrafficConfig{}, 5);
  ASSERT_EQ(again.movers().size(), traffic_->movers().size());
  for (std::size_t i = 0; i < again.movers().size(); ++i) {
    EXPECT_EQ(again.movers()[i].t_on_s, traffic_->movers()[i].t_on_s);
    EXPECT_EQ(again.movers()[i].s0_m, traffic_->movers()[i].s0_m);
  }
}

TEST_F(TrafficTest, RenderedScanShowsTheMoversAndNoTrafficChangesNothing) {
  const SensorModel sensor = sensor_preset("hdl64");
  const BeamCalibration calib = draw_beam_calibration(sensor, 5);
  TrafficConfig off;
  off.enabled = false;
  const Traffic none(scenario_->trajectory, scenario_->world, off, 5);
  EXPECT_TRUE(none.movers().empty());
  int frames_checked = 0;
  for (std::size_t k = 50; k < scenario_->frames && frames_checked < 3; k += 37) {
    const double t = k * scenario_->frame_period_s;
    std::vector<Primitive> boxes;
    traffic_->primitives_at(t, scenario_->frame_pose(k).translation().head<2>(), 30, &boxes);
    if (boxes.empty()) continue;
    SweepPoses poses;
    poses.T_world_lidar = scenario_->frame_pose(k);
    const Scan plain = render_scan(scenario_->world, sensor, calib, poses, 5, k);
    const Scan empty = render_scan(scenario_->world, sensor, calib, poses, 5, k, &none, t);
    const Scan busy = render_scan(scenario_->world, sensor, calib, poses, 5, k, traffic_, t);
    ASSERT_EQ(plain.points.size(), empty.points.size());
    for (std::size_t i = 0; i < plain.points.size(); ++i) {
      ASSERT_EQ(plain.points[i].x, empty.points[i].x);
      ASSERT_EQ(plain.points[i].intensity, empty.points[i].intensity);
    }
    // Points inside a mover's box (grown by 0.3 m for the noise and its sweep motion).
    auto inside = [&](const Scan& scan) {
      std::size_t n = 0;
      for (const auto& p : scan.points) {
        const Eigen::Vector3d w = poses.T_world_lidar * Eigen::Vector3d(p.x, p.y, p.z);
        for (const Primitive& b : boxes) {
          const double dx = w.x() - b.cx, dy = w.y() - b.cy;
          const double lx = b.cos_yaw * dx + b.sin_yaw * dy, ly = -b.sin_yaw * dx + b.cos_yaw * dy;
          if (std::abs(lx) < b.hx + 0.3 && std::abs(ly) < b.hy + 0.3 && w.z() > b.z0 + 0.1 && w.z() < b.z1 + 0.3) {
            ++n;
            break;
          }
        }
      }
      return n;
    };
    EXPECT_GT(inside(busy), inside(plain) + 30) << "frame " << k;
    ++frames_checked;
  }
  EXPECT_GT(frames_checked, 0);
}

}  // namespace
}  // namespace scfloam::sim
