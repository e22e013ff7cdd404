// The three scenario kinds: a grid city with loops, a long avenue, and a replayed path.
#include "scfloam/sim/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "scfloam/error.hpp"
#include "scfloam/sim/rng.hpp"

namespace scfloam::sim {
namespace {
using Vec2 = Eigen::Vector2d;
constexpr double kLaneOffset = 1.6;  // drive on the right lane

Street random_street(Rng& rng, std::vector<Vec2> line, double half_width) {
  Street s;
  s.centerline = std::move(line);
  s.half_width_m = half_width;
  s.sidewalk_m = rng.uniform(2.5, 4.5);
  s.tree_lined = rng.chance(0.4);
  s.parking = rng.chance(0.75);
  return s;
}

// A grid street edge, straight or gently curved (quadratic Bezier).
std::vector<Vec2> edge_line(Rng& rng, const Vec2& a, const Vec2& b) {
  if (!rng.chance(0.2)) return {a, b};
  const Vec2 d = b - a;
  const Vec2 ctrl = 0.5 * (a + b) + Vec2(-d.y(), d.x()) * rng.uniform(-0.16, 0.16);
  // Long first and last chords leave room to round the corners at both intersections.
  std::vector<Vec2> out;
  for (double u : {0.0, 0.25, 0.3125, 0.375, 0.4375, 0.5, 0.5625, 0.625, 0.6875, 0.75, 1.0})
    out.push_back((1 - u) * (1 - u) * a + 2 * u * (1 - u) * ctrl + u * u * b);
  return out;
}

// Rounds every corner of a street polyline with a circular arc of radius_m (smaller where
// the neighbouring segments are short), so the driven path stays inside intersections.
std::vector<Vec2> fillet_corners(const std::vector<Vec2>& pts, double radius_m) {
  std::vector<Vec2> in;
  for (const auto& p : pts)
    if (in.empty() || (p - in.back()).norm() > 1e-6) in.push_back(p);
  if (in.size() < 3) return in;
  std::vector<Vec2> out{in.front()};
  for (std::size_t i = 1; i + 1 < in.size(); ++i) {
    const Vec2 d1 = (in[i] - in[i - 1]).normalized(), d2 = (in[i + 1] - in[i]).normalized();
    const double cross = d1.x() * d2.y() - d1.y() * d2.x();
    const double turn = std::atan2(cross, d1.dot(d2));  // signed, left positive
    if (std::abs(turn) < 1e-3) {
      out.push_back(in[i]);
      continue;
    }
    const double half_tan = std::tan(std::abs(turn) / 2);
    const double tangent = std::min({radius_m * half_tan, 0.45 * (in[i] - in[i - 1]).norm(),
                                     0.45 * (in[i + 1] - in[i]).norm()});
    const double r = tangent / half_tan;
    const Vec2 start = in[i] - d1 * tangent;
    const Vec2 left(-d1.y(), d1.x());
    const Vec2 center = start + left * (turn > 0 ? r : -r);
    const int steps = std::max(2, static_cast<int>(std::abs(turn) * r / 0.5));
    for (int k = 0; k <= steps; ++k) {
      const double a = turn * k / steps;
      const Vec2 rel = start - center;
      out.push_back(center + Vec2(std::cos(a) * rel.x() - std::sin(a) * rel.y(), std::sin(a) * rel.x() + std::cos(a) * rel.y()));
    }
  }
  out.push_back(in.back());
  return out;
}

double max_curvature(const std::vector<Vec2>& p) {
  double worst = 0;
  for (std::size_t i = 4; i + 4 < p.size(); ++i) {
    const Vec2 a = p[i] - p[i - 4], b = p[i + 4] - p[i];
    const double turn = std::abs(std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b)));
    worst = std::max(worst, turn / (0.5 * (a.norm() + b.norm())));
  }
  return worst;
}

std::vector<Vec2> drive_lane(const std::vector<Vec2>& centerline) {
  // Corners become 11 m arcs (the right lane turns at ~9.4 m right, ~12.6 m left: <= 0.55
  // rad/s at 5 m/s, inside the intersection); a light gaussian then eases the curvature in.
  std::vector<Vec2> lane =
      smooth_path(offset_path(smooth_path(fillet_corners(centerline, 11.0), 0.5, 0.5), kLaneOffset), 0.5, 3.0);
  // Skewed corners next to short segments got smaller arcs: ease them (only there, within
  // 20 m, so other corners are not cut) until the radius is >= 8 m.
  for (int pass = 0; pass < 8 && max_curvature(lane) > 1.0 / 8.0; ++pass) {
    const int n = static_cast<int>(lane.size()), reach = 40;  // samples are ~0.5 m apart
    std::vector<Vec2> eased(n);
    for (int i = 0; i < n; ++i) {  // gaussian, sigma 8 samples (~4 m), same indices
      Vec2 acc = Vec2::Zero();
      double wsum = 0;
      for (int k = -24; k <= 24; ++k) {
        const double w = std::exp(-0.5 * (k / 8.0) * (k / 8.0));
        acc += w * lane[std::clamp(i + k, 0, n - 1)];
        wsum += w;
      }
      eased[i] = acc / wsum;
    }
    std::vector<double> weight(n, 0.0);
    for (int i = 4; i + 4 < n; ++i) {
      const Vec2 a = lane[i] - lane[i - 4], b = lane[i + 4] - lane[i];
      const double k = std::abs(std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b))) / (0.5 * (a.norm() + b.norm()));
      if (k <= 1.0 / 8.0) continue;
      for (int j = std::max(0, i - reach); j < std::min(n, i + reach); ++j)
        weight[j] = std::max(weight[j], 1.0 - std::abs(j - i) / static_cast<double>(reach));
    }
    for (int i = 0; i < n; ++i) lane[i] = (1 - weight[i]) * lane[i] + weight[i] * eased[i];
  }
  return lane;
}

double path_length(const std::vector<Vec2>& p) {
  double L = 0;
  for (std::size_t i = 1; i < p.size(); ++i) L += (p[i] - p[i - 1]).norm();
  return L;
}

void finish(Scenario& sc, const std::vector<Vec2>& lane, std::size_t frames, std::uint64_t seed,
            double mount_height_m) {
  DriveLimits limits;
  limits.mount_height_m = mount_height_m;
  const World& w = sc.world;
  sc.trajectory = drive_path(lane, (frames + 1) * sc.frame_period_s,
                             [&w](double x, double y) { return w.terrain_m.sample(x, y); }, limits, seed);
  sc.frames = std::min<std::size_t>(frames, static_cast<std::size_t>(sc.trajectory.duration_s() / sc.frame_period_s));
  sc.route_length_m = 0;
  for (std::size_t k = 1; k < sc.frames; ++k)
    sc.route_length_m += (sc.frame_pose(k).translation() - sc.frame_pose(k - 1).translation()).norm();
}
}  // namespace

Scenario make_loops_scenario(std::uint64_t seed, std::size_t frames, double mount_height_m) {
  if (frames < 2) throw Error("the loops route needs at least 2 frames");
  Rng rng(hash_combine(seed, 0x100B5ULL));
  const double needed_m = frames * 0.1 * 8.5 + 100;  // mean speed is ~7.5-9 m/s
  // The opposite-direction revisit starts after ~8 block edges: fit it into the route.
  const double block = std::clamp(needed_m / 12.0, 60.0, 110.0);
  // The first loop: w x h blocks, longer than 1 km when the route is long enough for it.
  int w = 1, h = 1;
  if (needed_m >= 2800)
    while (2 * (w + h) * block < 1150) (w <= h ? w : h) += 1;
  const int i_min = -1, i_max = w + 2, j_min = -2, j_max = h + 1;
  std::map<int, double> col_x, row_y;
  for (int i = i_min; i <= i_max; ++i) col_x[i] = (i == i_min ? 0 : col_x[i - 1] + block * rng.uniform(0.7, 1.3));
  for (int j = j_min; j <= j_max; ++j) row_y[j] = (j == j_min ? 0 : row_y[j - 1] + block * rng.uniform(0.7, 1.3));
  const double rot = rng.uniform(0, 2 * M_PI);
  const Eigen::Rotation2Dd R(rot);
  std::map<std::pair<int, int>, Vec2> node;
  for (int i = i_min; i <= i_max; ++i)
    for (int j = j_min; j <= j_max; ++j) {
      // One draw per statement (rng.hpp), in the order that keeps earlier versions' cities.
      const double dy = rng.uniform(-0.08, 0.08) * block;
      const double dx = rng.uniform(-0.08, 0.08) * block;
      node[{i, j}] = R * Vec2(col_x[i] + dx, row_y[j] + dy);
    }

  // Streets: every grid edge; avenues are wider along a whole grid line.
  std::map<int, double> col_hw, row_hw;
  for (int i = i_min; i <= i_max; ++i) col_hw[i] = rng.chance(0.25) ? rng.uniform(7.5, 9) : rng.uniform(6, 7);
  for (int j = j_min; j <= j_max; ++j) row_hw[j] = rng.chance(0.25) ? rng.uniform(7.5, 9) : rng.uniform(6, 7);
  std::vector<Street> streets;
  std::map<std::pair<std::pair<int, int>, std::pair<int, int>>, std::size_t> edge_index;
  for (int i = i_min; i <= i_max; ++i)
    for (int j = j_min; j <= j_max; ++j) {
      if (i < i_max) {
        edge_index[{{i, j}, {i + 1, j}}] = streets.size();
        streets.push_back(random_street(rng, edge_line(rng, node[{i, j}], node[{i + 1, j}]), row_hw[j]));
      }
      if (j < j_max) {
        edge_index[{{i, j}, {i, j + 1}}] = streets.size();
        streets.push_back(random_street(rng, edge_line(rng, node[{i, j}], node[{i, j + 1}]), col_hw[i]));
      }
    }

  // Node sequence: loop (CCW), same-direction revisit, neighbouring block clockwise, then
  // north along the loop's first-driven western street in the opposite direction.
  std::vector<std::pair<int, int>> seq = {{0, 0}, {w, 0}, {w, h}, {0, h}, {0, 0}, {1, 0},
                                          {1, -1}, {0, -1}, {0, 0}, {0, h}};
  std::vector<std::pair<int, int>> nodes;
  for (std::size_t k = 0; k + 1 < seq.size(); ++k) {
    auto [i, j] = seq[k];
    const auto [ti, tj] = seq[k + 1];
    if (nodes.empty()) nodes.push_back({i, j});
    while (i != ti || j != tj) {
      i += (ti > i) - (ti < i);
      j += (tj > j) - (tj < j);
      nodes.push_back({i, j});
    }
  }
  auto append_edge = [&](std::vector<Vec2>& line, std::pair<int, int> a, std::pair<int, int> b) {
    const bool forward = edge_index.count({a, b}) > 0;
    const Street& st = streets[forward ? edge_index[{a, b}] : edge_index[{b, a}]];
    std::vector<Vec2> pts = st.centerline;
    if (!forward) std::reverse(pts.begin(), pts.end());
    line.insert(line.end(), pts.begin() + (line.empty() ? 0 : 1), pts.end());
  };
  std::vector<Vec2> center;
  for (std::size_t k = 0; k + 1 < nodes.size(); ++k) append_edge(center, nodes[k], nodes[k + 1]);
  // Random drive (never a U-turn) until the route is long enough.
  while (path_length(center) < needed_m * 1.15 + 200) {
    const auto cur = nodes.back(), prev = nodes[nodes.size() - 2];
    const int di = cur.first - prev.first, dj = cur.second - prev.second;
    const std::pair<int, int> options[3] = {{di, dj}, {-dj, di}, {dj, -di}};  // straight, left, right
    const double pick = rng.uniform();
    int choice = pick < 0.5 ? 0 : (pick < 0.75 ? 1 : 2);
    for (int tries = 0; tries < 3; ++tries, choice = (choice + 1) % 3) {
      const std::pair<int, int> next{cur.first + options[choice].first, cur.second + options[choice].second};
      if (next.first >= i_min && next.first <= i_max && next.second >= j_min && next.second <= j_max) {
        append_edge(center, cur, next);
        nodes.push_back(next);
        break;
      }
    }
  }

  Scenario sc;
  const WorldBounds bounds = bounds_of(streets, 80);
  sc.world = build_city(streets, make_rolling_terrain(bounds, seed, 0.04), seed, &sc.stats);
  finish(sc, drive_lane(center), frames, seed, mount_height_m);
  sc.description = "loops: grid city " + std::to_string(i_max - i_min) + "x" + std::to_string(j_max - j_min) +
                   " blocks (~" + std::to_string(static_cast<int>(block)) + " m), first loop " +
                   std::to_string(w) + "x" + std::to_string(h) + " blocks";
  return sc;
}

Scenario make_straight_scenario(std::uint64_t seed, std::size_t frames, double mount_height_m) {
  if (frames < 2) throw Error("the straight route needs at least 2 frames");
  Rng rng(hash_combine(seed, 0x5A1CULL));
  const double length = frames * 0.1 * 12.0 + 200;
  std::vector<Vec2> avenue;
  Vec2 p(0, 0);
  double heading = 0, turn = 0;
  for (double s = 0; s <= length; s += 5) {
    avenue.push_back(p);
    turn = 0.9 * turn + rng.normal(0, 0.0015);  // gentle, smooth bends
    heading += turn * 5;
    p += 5 * Vec2(std::cos(heading), std::sin(heading));
  }
  std::vector<Street> streets{random_street(rng, avenue, 7.0)};
  for (double s = rng.uniform(40, 100); s < length; s += rng.uniform(60, 140)) {
    const std::size_t i = std::min(avenue.size() - 2, static_cast<std::size_t>(s / 5));
    const Vec2 t = (avenue[i + 1] - avenue[i]).normalized(), n(-t.y(), t.x());
    for (int side = -1; side <= 1; side += 2)
      if (rng.chance(0.7)) {
        const double half_width = rng.uniform(5.5, 7);
        const double street_len = rng.uniform(60, 150);
        streets.push_back(random_street(rng, {avenue[i], avenue[i] + side * n * street_len}, half_width));
      }
  }
  Scenario sc;
  sc.world = build_city(streets, make_rolling_terrain(bounds_of(streets, 80), seed, 0.04), seed, &sc.stats);
  finish(sc, drive_lane(avenue), frames, seed, mount_height_m);
  sc.description = "straight: one long avenue with side streets, no loops";
  return sc;
}

Scenario make_replay_scenario(const PoseList& T_lidar0_lidar, std::uint64_t seed, std::size_t frames,
                              double mount_height_m) {
  if (T_lidar0_lidar.size() < 2) throw Error("a replayed trajectory needs at least 2 poses");
  Rng rng(hash_combine(seed, 0x4E91A7ULL));
  const std::size_t used = frames == 0 ? T_lidar0_lidar.size() : std::min(frames, T_lidar0_lidar.size());
  // The street follows the driven path (all of it, so later loops exist in the world too).
  std::vector<Vec2> path;
  std::vector<Eigen::Vector3d> ground;
  for (const auto& T : T_lidar0_lidar) {
    const Eigen::Vector3d g = T.translation() - T.linear().col(2) * mount_height_m;
    ground.push_back(g);
    const Vec2 xy(T.translation().x(), T.translation().y());
    if (path.empty() || (xy - path.back()).norm() > 1.5) path.push_back(xy);
  }
  if (path.size() < 2) path.push_back(path.back() + Vec2(1, 0));
  std::vector<Street> streets;
  Street main = random_street(rng, path, 7.0);
  main.extra_setback_m = 0.5;
  streets.push_back(main);
  double s = 0;
  double next_side = rng.uniform(40, 120);
  for (std::size_t i = 1; i < path.size(); ++i) {
    s += (path[i] - path[i - 1]).norm();
    if (s < next_side) continue;
    next_side = s + rng.uniform(70, 160);
    const Vec2 t = (path[std::min(i + 2, path.size() - 1)] - path[i > 1 ? i - 2 : 0]).normalized();
    const Vec2 n(-t.y(), t.x());
    for (int side = -1; side <= 1; side += 2)
      if (rng.chance(0.6)) {
        const double a = rng.uniform(-0.35, 0.35);
        const Vec2 dir = Eigen::Rotation2Dd(a) * (side * n);
        const double half_width = rng.uniform(5.5, 7);
        const double street_len = rng.uniform(60, 150);
        streets.push_back(random_street(rng, {path[i], path[i] + dir * street_len}, half_width));
      }
  }
  Scenario sc;
  const WorldBounds bounds = bounds_of(streets, 80);
  sc.world = build_city(streets, fit_terrain(bounds, ground), seed, &sc.stats);
  sc.trajectory.dt_s = 0.1;
  sc.trajectory.smooth = true;  // one pose per frame: a sweep in between moves along a curve
  sc.trajectory.T_world_lidar = T_lidar0_lidar;
  // x, y and the rotation are the file's; the height rides on the (single-valued) terrain,
  // since ground truths drift vertically between passes and the world cannot follow both.
  for (auto& T : sc.trajectory.T_world_lidar)
    T.translation().z() = sc.world.terrain_m.sample(T.translation().x(), T.translation().y()) + mount_height_m;
  sc.frames = used;
  sc.route_length_m = 0;
  for (std::size_t k = 1; k < used; ++k)
    sc.route_length_m += (sc.frame_pose(k).translation() - sc.frame_pose(k - 1).translation()).norm();
  sc.description = "replay: " + std::to_string(T_lidar0_lidar.size()) + " poses, street along the path";
  return sc;
}

}  // namespace scfloam::sim
