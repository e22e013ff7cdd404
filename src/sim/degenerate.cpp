// The degenerate scenes: tunnel, open field, stationary car, data gap, missing beams.
#include "scfloam/sim/degenerate.hpp"

#include <algorithm>
#include <cmath>

#include "scfloam/error.hpp"
#include "scfloam/sim/rng.hpp"

namespace scfloam::sim {
using Vec2 = Eigen::Vector2d;

Scenario make_patrol_scenario(std::uint64_t seed, std::size_t frames, double mount_height_m);

namespace {
constexpr double kFramePeriod = 0.1;

void set_route_length(Scenario& sc) {
  sc.route_length_m = 0;
  for (std::size_t k = 1; k < sc.frames; ++k)
    sc.route_length_m += (sc.frame_pose(k).translation() - sc.frame_pose(k - 1).translation()).norm();
}

std::function<double(double, double)> ground_of(const World& w) {
  return [&w](double x, double y) { return w.terrain_m.sample(x, y); };
}

// ---- tunnel: 80 m of street, a straight tunnel, 80 m of street ---------------------------
Scenario tunnel(std::uint64_t seed, std::size_t frames, double mount) {
  constexpr double kOutside = 80, kHalfWidth = 8.0, kHeight = 6.0, kCruise = 12.5;
  if (frames == 0) frames = 370;  // ~300 m of tunnel at ~12.5 m/s
  Rng rng(hash_combine(seed, 0x7E77E1ULL));
  const double phase = rng.uniform(0, 2 * M_PI);
  auto speed = [&](double t) { return ease(t, 0, 4, kCruise - 1, kCruise) + 1.0 * std::sin(2 * M_PI * t / 25 + phase) * ease(t, 0, 4, 0, 1); };
  const std::vector<double> s = integrate_speed(speed, (frames + 1) * kFramePeriod, 0.01);
  const double route = s[frames * 10];
  const double x_in = kOutside, x_out = route - kOutside;
  if (x_out - x_in < 40) throw Error("the tunnel scene needs at least 160 frames");

  Street street;
  street.centerline = {Vec2(-150, 0), Vec2(route + 250, 0)};
  street.half_width_m = 6.0;
  street.sidewalk_m = 3.0;
  street.parking = true;
  Scenario sc;
  const WorldBounds bounds = bounds_of({street}, 120);
  sc.world = build_city({street}, make_rolling_terrain(bounds, seed, 0.0), seed, &sc.stats);
  // The hill: nothing stands between the portals but the tunnel's concrete.
  auto& prims = sc.world.primitives;
  prims.erase(std::remove_if(prims.begin(), prims.end(),
                             [&](const Primitive& p) {
                               double x0, y0, x1, y1;
                               p.bounds(x0, y0, x1, y1);
                               return x1 > x_in - 1 && x0 < x_out + 1 && y1 > -80 && y0 < 80;
                             }),
              prims.end());
  const float concrete = 0.3f;
  auto box = [&](double xa, double xb, double ya, double yb, double za, double zb) {
    prims.push_back(make_box(0.5 * (xa + xb), 0.5 * (ya + yb), 0, 0.5 * (xb - xa), 0.5 * (yb - ya), za, zb,
                             SurfaceKind::wall, concrete));
  };
  const double hill_top = 15, depth = 70;
  box(x_in, x_out, kHalfWidth, kHalfWidth + depth, -1, hill_top);        // left wall + hill
  box(x_in, x_out, -kHalfWidth - 2, kHalfWidth, kHeight, hill_top);      // ceiling + hill
  // Right wall with an emergency bay (4 m long, 1.5 m deep) every 150 m: the only features.
  double x = x_in;
  for (double bay = x_in + 75; bay + 2 < x_out; bay += 150) {
    box(x, bay - 2, -kHalfWidth - depth, -kHalfWidth, -1, hill_top);
    box(bay - 2, bay + 2, -kHalfWidth - depth, -kHalfWidth - 1.5, -1, hill_top);
    x = bay + 2;
  }
  box(x, x_out, -kHalfWidth - depth, -kHalfWidth, -1, hill_top);
  sc.world.build_index();

  sc.trajectory = drive_arclength({Vec2(0, -1.6), Vec2(route + 300, -1.6)}, false, s, 0.01,
                                  ground_of(sc.world), mount);
  sc.frames = frames;
  for (std::size_t k = 0; k < frames; ++k) {
    const double xk = sc.frame_pose(k).translation().x();
    if (xk >= x_in && sc.degenerate_first_frame == 0) sc.degenerate_first_frame = k;
    if (xk <= x_out) sc.degenerate_end_frame = k + 1;
  }
  set_route_length(sc);
  sc.description = "tunnel: " + std::to_string(static_cast<int>(x_out - x_in)) +
                   " m straight tunnel (smooth walls, a bay every 150 m) between 80 m of street";
  return sc;
}

// ---- open field: a village, open ground with a few far barns and trees, a village ---------
// A farm building turned at random, half extents and height drawn from [lo, hi] ranges. One
// draw per statement (rng.hpp), in the order that keeps earlier versions' scenes.
Primitive farm_building(Rng& rng, double x, double y, double ground, std::pair<double, double> half_x,
                        std::pair<double, double> half_y, std::pair<double, double> height) {
  const float reflectance = static_cast<float>(rng.uniform(0.2, 0.5));
  const double top = ground + rng.uniform(height.first, height.second);
  const double hy = rng.uniform(half_y.first, half_y.second);
  const double hx = rng.uniform(half_x.first, half_x.second);
  const double yaw = rng.uniform(0, M_PI);
  return make_box(x, y, yaw, hx, hy, ground - 1, top, SurfaceKind::wall, reflectance);
}

Scenario open_field(std::uint64_t seed, std::size_t frames, double mount) {
  // The villages at both ends give the odometry its speed before the field and structure to
  // recover on after it, as the streets around the tunnel do.
  constexpr double kYard = 60;
  if (frames == 0) frames = 300;
  Rng rng(hash_combine(seed, 0xF1E1DULL));
  const double phase = rng.uniform(0, 2 * M_PI), bend_phase = rng.uniform(0, 2 * M_PI);
  auto speed = [&](double t) { return 9.0 + 1.2 * std::sin(2 * M_PI * t / 30 + phase) - 1.2 * std::sin(phase); };
  const std::vector<double> s = integrate_speed(speed, (frames + 1) * kFramePeriod, 0.01);
  const double drive = s[frames * 10], route = drive + 300;
  if (drive < 2 * kYard + 40) throw Error("the open-field scene needs at least 160 frames");
  // A gently bending farm track (curvature <= 0.004 /m).
  auto lane_y = [&](double x) { return 12 * std::sin(2 * M_PI * x / 350 + bend_phase); };
  std::vector<Vec2> lane;
  for (double x = 0; x <= route; x += 1.0) lane.emplace_back(x, lane_y(x));

  Scenario sc;
  const WorldBounds bounds{-200, -300, route + 200, 300};
  sc.world.terrain_m = make_rolling_terrain(bounds, seed, 0.015);
  sc.world.road_edge_distance.reset(bounds.xmin, bounds.ymin, 4.0, static_cast<int>((bounds.xmax - bounds.xmin) / 4) + 2,
                                    static_cast<int>((bounds.ymax - bounds.ymin) / 4) + 2, -1.0f);
  sc.world.curb_height_m = 0;  // no curbs: one continuous surface
  sc.world.road_reflectance = 0.3f;
  const auto& terrain = sc.world.terrain_m;
  // Each yard is a village street: farm buildings 8-16 m from the track on both sides, one
  // every 8-14 m, turned at random.
  for (const double x0 : {-30.0, drive - kYard}) {
    for (const double side : {-1.0, 1.0}) {
      for (double x = x0 + rng.uniform(0, 8); x < x0 + kYard + 30; x += rng.uniform(8, 14)) {
        const double yo = lane_y(x) + side * rng.uniform(8, 16), g = terrain.sample(x, yo);
        sc.world.primitives.push_back(farm_building(rng, x, yo, g, {2, 4}, {3, 6}, {3, 8}));
        ++sc.stats.buildings;
      }
    }
  }
  for (double xo = kYard + rng.uniform(30, 90); xo < route; xo += rng.uniform(120, 200)) {
    const double side = rng.chance(0.5) ? 1 : -1;
    const double yo = lane_y(xo) + side * rng.uniform(45, 110);
    const double g = terrain.sample(xo, yo);
    if (rng.chance(0.5)) {  // a barn
      sc.world.primitives.push_back(farm_building(rng, xo, yo, g, {4, 6}, {7, 12}, {5, 8}));
      ++sc.stats.buildings;
    } else {  // a group of trees
      for (int i = rng.uniform_int(3, 5); i > 0; --i) {
        const double tx = xo + rng.uniform(-10, 10), ty = yo + rng.uniform(-10, 10), tg = terrain.sample(tx, ty);
        const double height = rng.uniform(6, 10);
        // One draw per statement (rng.hpp), in the order that keeps earlier versions' scenes.
        const float trunk_refl = static_cast<float>(rng.uniform(0.25, 0.4));
        const double trunk_r = rng.uniform(0.15, 0.3);
        sc.world.primitives.push_back(make_cylinder(tx, ty, trunk_r, tg - 0.5, tg + 0.5 * height,
                                                    SurfaceKind::trunk, trunk_refl));
        const float crown_refl = static_cast<float>(rng.uniform(0.35, 0.6));
        const double crown_r = rng.uniform(2, 3.5);
        sc.world.primitives.push_back(make_ellipsoid(tx, ty, tg + 0.7 * height, crown_r, 0.3 * height,
                                                     SurfaceKind::vegetation, crown_refl, 1.0f));
        ++sc.stats.trees;
      }
    }
  }
  sc.world.build_index();
  sc.trajectory = drive_arclength(lane, false, s, 0.01, ground_of(sc.world), mount);
  sc.frames = frames;
  for (std::size_t k = 0; k < frames; ++k) {
    const double xk = sc.frame_pose(k).translation().x();
    if (xk >= kYard && sc.degenerate_first_frame == 0) sc.degenerate_first_frame = k;
    if (xk <= drive - kYard) sc.degenerate_end_frame = k + 1;
  }
  set_route_length(sc);
  sc.description = "open-field: 60 m of village street, " + std::to_string(static_cast<int>(drive - 2 * kYard)) +
                   " m of flat open ground (a barn or a group of trees every 120-200 m, 45-110 m off the track), 60 m of village street";
  return sc;
}

// ---- stationary: stop on the avenue, stand, drive on ---------------------------------------
Scenario stationary(std::uint64_t seed, std::size_t frames, double mount) {
  if (frames == 0) frames = 760;  // 60 s standing
  const double stand_s = frames * kFramePeriod - 16;
  if (stand_s < 1) throw Error("the stationary scene needs at least 170 frames");
  Scenario sc = make_straight_scenario(seed, 200, mount);
  std::vector<Vec2> lane;  // the avenue's lane, as the straight route drives it
  for (const Pose& T : sc.trajectory.T_world_lidar) lane.push_back(T.translation().head<2>());
  constexpr double kCruise = 8.0, kStop = 3.0, kStopped = 8.0;
  const double go = kStopped + stand_s;
  auto speed = [&](double t) { return t < go ? ease(t, kStop, kStopped, kCruise, 0) : ease(t, go, go + 6, 0, kCruise); };
  std::vector<double> s = integrate_speed(speed, (frames + 1) * kFramePeriod, 0.01);
  // Standing still means exactly the same pose, not a creep of rounding errors.
  for (std::size_t k = 1; k < s.size(); ++k)
    if (k * 0.01 >= kStopped && k * 0.01 <= go) s[k] = s[k - 1];
  sc.trajectory = drive_arclength(lane, false, s, 0.01, ground_of(sc.world), mount);
  sc.frames = frames;
  // Frames strictly inside the standstill (the boundary frames still see the braking's pitch).
  sc.degenerate_first_frame = static_cast<std::size_t>(std::ceil(kStopped / kFramePeriod)) + 1;
  sc.degenerate_end_frame = static_cast<std::size_t>(std::floor(go / kFramePeriod));
  set_route_length(sc);
  sc.description = "stationary: the avenue; stops at 3-8 s, stands " + std::to_string(static_cast<int>(stand_s)) +
                   " s with traffic around, drives on";
  return sc;
}

// ---- gap: 10 frames (1 s) missing in the middle of a city drive ---------------------------
Scenario gap(std::uint64_t seed, std::size_t frames, double mount) {
  if (frames == 0) frames = 300;
  constexpr std::size_t kMissing = 10;
  if (frames < 4) throw Error("the gap scene needs at least 4 frames");
  Scenario sc = make_loops_scenario(seed, frames + kMissing, mount);
  const std::size_t first_after = frames / 2;
  sc.frames = frames;
  for (std::size_t k = 0; k < frames; ++k)
    sc.frame_times_s.push_back((k < first_after ? k : k + kMissing) * kFramePeriod);
  sc.degenerate_first_frame = first_after;
  sc.degenerate_end_frame = first_after + 1;
  set_route_length(sc);
  sc.description = "gap: " + sc.description + "; frames " + std::to_string(first_after) + ".." +
                   std::to_string(first_after + kMissing - 1) + " of the drive are missing (1 s)";
  return sc;
}

// ---- half-beams: every other beam absent, then the upper half -----------------------------
Scenario half_beams(std::uint64_t seed, std::size_t frames, double mount) {
  if (frames == 0) frames = 300;
  if (frames < 8) throw Error("the half-beams scene needs at least 8 frames");
  Scenario sc = make_loops_scenario(seed, frames, mount);
  const std::size_t a = frames / 4, b = frames / 2, c = 3 * frames / 4;
  sc.beam_losses.push_back({a, b, 2, 0.0});
  sc.beam_losses.push_back({b, c, 1, 0.5});
  sc.degenerate_first_frame = a;
  sc.degenerate_end_frame = c;
  sc.description = "half-beams: " + sc.description + "; every other beam absent in frames " + std::to_string(a) +
                   ".." + std::to_string(b - 1) + ", the upper half in " + std::to_string(b) + ".." +
                   std::to_string(c - 1);
  return sc;
}
}  // namespace

std::vector<std::string> degenerate_scenario_names() {
  return {"tunnel", "open-field", "stationary", "gap", "half-beams", "patrol"};
}

Scenario make_degenerate_scenario(const std::string& name, std::uint64_t seed, std::size_t frames,
                                  double mount_height_m) {
  if (name == "tunnel") return tunnel(seed, frames, mount_height_m);
  if (name == "open-field") return open_field(seed, frames, mount_height_m);
  if (name == "stationary") return stationary(seed, frames, mount_height_m);
  if (name == "gap") return gap(seed, frames, mount_height_m);
  if (name == "half-beams") return half_beams(seed, frames, mount_height_m);
  if (name == "patrol") return make_patrol_scenario(seed, frames, mount_height_m);
  std::string known;
  for (const auto& n : degenerate_scenario_names()) known += (known.empty() ? "" : ", ") + n;
  throw Error("unknown scenario `" + name + "` (known: " + known + ")");
}

}  // namespace scfloam::sim
