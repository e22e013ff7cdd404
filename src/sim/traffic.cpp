// Traffic planning and placement. Every mover is a closed-form function of time along the
// ego path, so a frame (or a single column of a sweep) can place it independently.
#include "scfloam/sim/traffic.hpp"

#include <algorithm>
#include <cmath>

#include "scfloam/sim/rng.hpp"

namespace scfloam::sim {
namespace {
using Vec2 = Eigen::Vector2d;
constexpr double kOncomingLateral = -3.2;  // opposite lane: 2 lane offsets to the left
constexpr double kFarGap = 90;             // leaders/followers enter and leave this far away
constexpr double kRampS = 12;              // ... over this long
constexpr double kVisibleArc = 110;        // oncoming cars exist within this arclength

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

// Exponential waiting time for a Poisson process of `per_minute` events.
double next_gap_s(Rng& rng, double per_minute) {
  return -std::log(1.0 - rng.uniform()) * 60.0 / per_minute;
}

void car_shape(Rng& rng, Mover* m) {
  const double kind = rng.uniform();
  m->reflectance = static_cast<float>(rng.uniform(0.1, 0.8));
  if (kind < 0.1) {  // bus or truck
    m->half_len_m = rng.uniform(4.5, 6.0);
    m->half_width_m = 1.25;
    m->body_bottom_m = 0.4;
    m->body_top_m = rng.uniform(3.0, 3.4);
    m->cabin_half_len_m = 0;
  } else if (kind < 0.25) {  // van
    m->half_len_m = rng.uniform(2.5, 3.2);
    m->half_width_m = 1.0;
    m->body_bottom_m = 0.35;
    m->body_top_m = rng.uniform(2.0, 2.6);
    m->cabin_half_len_m = 0;
  } else {
    m->half_len_m = rng.uniform(1.95, 2.45);
    m->half_width_m = rng.uniform(0.85, 0.95);
    m->body_bottom_m = 0.3;
    m->body_top_m = rng.uniform(0.85, 1.0);
    m->cabin_half_len_m = m->half_len_m * rng.uniform(0.5, 0.6);
    m->cabin_half_width_m = m->half_width_m - 0.08;
    m->cabin_top_m = rng.uniform(1.4, 1.6);
  }
}
}  // namespace

void ArcPath::at(double s, Vec2* position, Vec2* heading) const {
  const std::size_t n = points.size();
  s = std::clamp(s, 0.0, length());
  std::size_t i = static_cast<std::size_t>(std::upper_bound(s_m.begin(), s_m.end(), s) - s_m.begin());
  i = std::clamp<std::size_t>(i, 1, n - 1);
  const double seg = s_m[i] - s_m[i - 1];
  const double a = seg > 1e-9 ? (s - s_m[i - 1]) / seg : 0;
  *position = (1 - a) * points[i - 1] + a * points[i];
  // Heading over a few metres, so the 1 cm samples' jitter never shows.
  const std::size_t lo = i >= 20 ? i - 20 : 0, hi = std::min(n - 1, i + 20);
  const Vec2 d = points[hi] - points[lo];
  *heading = d.norm() > 1e-9 ? Vec2(d.normalized()) : Vec2(1, 0);
}

Traffic::Traffic(const SampledTrajectory& ego, const World& world, const TrafficConfig& config,
                 std::uint64_t seed)
    : dt_s_(ego.dt_s), world_(&world) {
  if (ego.T_world_lidar.size() < 2) return;
  double s = 0;
  for (std::size_t i = 0; i < ego.T_world_lidar.size(); ++i) {
    const Vec2 p = ego.T_world_lidar[i].translation().head<2>();
    if (i > 0) s += (p - ego_path_.points.back()).norm();
    ego_path_.points.push_back(p);
    ego_path_.s_m.push_back(s);
  }
  ego_s_ = ego_path_.s_m;
  if (!config.enabled || ego_path_.length() < 1) return;
  const double duration = ego.duration_s();
  Rng rng(hash_combine(seed, 0x7A4FF1CULL));

  // Oncoming cars: Poisson meeting times; a car that would run into the previous ones is
  // dropped (one lane, no overtaking).
  if (config.oncoming_per_minute > 0) {
    std::vector<Mover> lane;
    for (double t_meet = -5 + next_gap_s(rng, config.oncoming_per_minute); t_meet < duration + 5;
         t_meet += next_gap_s(rng, config.oncoming_per_minute)) {
      Mover m;
      m.kind = Mover::Kind::oncoming;
      m.speed_mps = -rng.uniform(5, 15);
      m.t0_s = t_meet;
      m.s0_m = ego_arclength(t_meet);
      m.lateral_m = kOncomingLateral;
      const double t_lo = std::max(0.0, t_meet - 1), t_hi = std::min(duration, t_meet + 1);
      const double ego_speed = (ego_arclength(t_hi) - ego_arclength(t_lo)) / std::max(1e-3, t_hi - t_lo);
      const double half_window = kVisibleArc / (ego_speed - m.speed_mps);
      m.t_on_s = t_meet - half_window;
      m.t_off_s = t_meet + half_window;
      car_shape(rng, &m);
      bool clear = true;
      for (std::size_t j = lane.size() > 4 ? lane.size() - 4 : 0; j < lane.size() && clear; ++j) {
        const Mover& o = lane[j];
        for (double t = std::max(m.t_on_s, o.t_on_s); t <= std::min(m.t_off_s, o.t_off_s); t += 0.25)
          if (std::abs((m.s0_m + m.speed_mps * (t - m.t0_s)) - (o.s0_m + o.speed_mps * (t - o.t0_s))) <
              m.half_len_m + o.half_len_m + 3) {
            clear = false;
            break;
          }
      }
      if (clear) lane.push_back(m);
    }
    movers_.insert(movers_.end(), lane.begin(), lane.end());
  }

  // A leader ahead and a follower behind in the ego lane, each present for 20-60 s stretches
  // covering about the configured share of the time; gap 8-35 m with a slow wobble.
  auto same_lane = [&](Mover::Kind kind, double fraction) {
    if (fraction <= 0) return;
    const double sign = kind == Mover::Kind::leader ? 1.0 : -1.0;
    double t = fraction >= 1 ? -1 : rng.uniform(0, 30) * (1 - fraction) / fraction;
    while (t < duration) {
      Mover m;
      m.kind = kind;
      m.t_on_s = t;
      m.t_off_s = t + rng.uniform(20, 60) + 2 * kRampS;
      car_shape(rng, &m);
      m.gap_m = sign * (rng.uniform(6, 30) + m.half_len_m + 2.2);
      m.wobble_m = rng.uniform(1, 4);
      m.wobble_rad_s = 2 * M_PI / rng.uniform(12, 30);
      m.wobble_phase = rng.uniform(0, 2 * M_PI);
      movers_.push_back(m);
      const double absent = fraction >= 1 ? 0 : (m.t_off_s - m.t_on_s) * (1 - fraction) / fraction;
      t = m.t_off_s + 1 + absent * rng.uniform(0.5, 1.5);
    }
  };
  same_lane(Mover::Kind::leader, config.leader_fraction);
  same_lane(Mover::Kind::follower, config.follower_fraction);

  // Pedestrians on the sidewalk of either side, found by stepping out of the road.
  if (config.pedestrians_per_minute > 0) {
    for (double t = next_gap_s(rng, config.pedestrians_per_minute); t < duration;
         t += next_gap_s(rng, config.pedestrians_per_minute)) {
      Mover m;
      m.kind = Mover::Kind::pedestrian;
      m.t0_s = t;
      m.t_on_s = t;
      m.t_off_s = t + 25;
      m.s0_m = ego_arclength(t) + rng.uniform(-20, 60);
      m.speed_mps = rng.uniform(0.9, 1.6);  // one draw per statement (rng.hpp)
      if (!rng.chance(0.5)) m.speed_mps = -m.speed_mps;
      const double side = rng.chance(0.5) ? 1.0 : -1.0;
      Vec2 p, h;
      ego_path_.at(m.s0_m, &p, &h);
      const Vec2 right(h.y(), -h.x());
      m.lateral_m = 0;
      for (double d = 2; d < 16; d += 0.25)
        if (world.road_edge_distance.sample(p.x() + side * d * right.x(), p.y() + side * d * right.y()) > 1.0) {
          m.lateral_m = side * d;
          break;
        }
      if (m.lateral_m == 0) continue;
      m.half_len_m = 0.18;
      m.half_width_m = 0.25;
      m.body_bottom_m = 0;
      m.body_top_m = rng.uniform(1.4, 1.6);
      m.cabin_half_len_m = 0.11;
      m.cabin_half_width_m = 0.1;
      m.cabin_top_m = m.body_top_m + 0.25;
      m.reflectance = static_cast<float>(rng.uniform(0.15, 0.6));
      movers_.push_back(m);
    }
  }
}

double Traffic::ego_arclength(double t_s) const {
  if (ego_s_.empty()) return 0;
  const double f = std::clamp(t_s / dt_s_, 0.0, static_cast<double>(ego_s_.size() - 1));
  const std::size_t i = std::min(static_cast<std::size_t>(f), ego_s_.size() - 2);
  const double a = f - static_cast<double>(i);
  return (1 - a) * ego_s_[i] + a * ego_s_[i + 1];
}

bool Traffic::state(const Mover& m, double t_s, Vec2* center, Vec2* heading) const {
  if (t_s < m.t_on_s || t_s > m.t_off_s || ego_s_.empty()) return false;
  double s;
  if (m.kind == Mover::Kind::leader || m.kind == Mover::Kind::follower) {
    const double ramp = smoothstep((t_s - m.t_on_s) / kRampS) * smoothstep((m.t_off_s - t_s) / kRampS);
    const double sign = m.gap_m > 0 ? 1.0 : -1.0;
    const double near = m.gap_m + sign * m.wobble_m * (1 + std::sin(m.wobble_rad_s * t_s + m.wobble_phase));
    s = ego_arclength(t_s) + ramp * near + (1 - ramp) * sign * kFarGap;
  } else {
    s = m.s0_m + m.speed_mps * (t_s - m.t0_s);
  }
  if (s < 0 || s > ego_path_.length()) return false;
  Vec2 p, h;
  ego_path_.at(s, &p, &h);
  *center = p + m.lateral_m * Vec2(h.y(), -h.x());
  // Oncoming cars face against the path; pedestrians face where they walk.
  *heading = (m.kind == Mover::Kind::oncoming || (m.kind == Mover::Kind::pedestrian && m.speed_mps < 0)) ? Vec2(-h) : h;
  return true;
}

void Traffic::primitives_at(double t_s, const Vec2& near, double radius_m, std::vector<Primitive>* out) const {
  for (const Mover& m : movers_) {
    Vec2 c, h;
    if (!state(m, t_s, &c, &h) || (c - near).norm() > radius_m + m.half_len_m) continue;
    const double g = world_->ground_height(c.x(), c.y());
    const double yaw = std::atan2(h.y(), h.x());
    const SurfaceKind kind = m.kind == Mover::Kind::pedestrian ? SurfaceKind::person : SurfaceKind::car;
    out->push_back(make_box(c.x(), c.y(), yaw, m.half_len_m, m.half_width_m, g + m.body_bottom_m,
                            g + m.body_top_m, kind, m.reflectance));
    if (m.cabin_half_len_m > 0) {
      const Vec2 cc = c - (m.kind == Mover::Kind::pedestrian ? 0.0 : 0.2) * h;
      out->push_back(make_box(cc.x(), cc.y(), yaw, m.cabin_half_len_m, m.cabin_half_width_m,
                              g + m.body_top_m - 0.05, g + m.cabin_top_m, kind, m.reflectance));
    }
  }
}

std::size_t Traffic::count_near(double t_s, const Vec2& near, double radius_m) const {
  std::size_t n = 0;
  for (const Mover& m : movers_) {
    Vec2 c, h;
    if (state(m, t_s, &c, &h) && (c - near).norm() <= radius_m) ++n;
  }
  return n;
}

}  // namespace scfloam::sim
