// Street-side placement of the city's objects. Every object is checked against the road
// edge distance field, so nothing stands on a roadway (parked cars keep clear of lanes).
#include "scfloam/sim/city.hpp"

#include <algorithm>
#include <cmath>

#include "scfloam/sim/rng.hpp"

namespace scfloam::sim {
namespace {
constexpr double kRoadCell = 0.5;   // resolution of the road edge distance field
constexpr double kRoadBand = 40.0;  // distances beyond this are stored as "far"

using Vec2 = Eigen::Vector2d;

// Signed distance to the nearest road edge on a 0.5 m raster (negative on roadways).
Raster2D rasterize_roads(const std::vector<Street>& streets, const Raster2D& terrain) {
  Raster2D r;
  const double xmin = terrain.x0, ymin = terrain.y0;
  const int nx = static_cast<int>((terrain.nx - 1) * terrain.cell_m / kRoadCell) + 1;
  const int ny = static_cast<int>((terrain.ny - 1) * terrain.cell_m / kRoadCell) + 1;
  r.reset(xmin, ymin, kRoadCell, nx, ny, static_cast<float>(kRoadBand));
  for (const auto& s : streets)
    for (std::size_t k = 0; k + 1 < s.centerline.size(); ++k) {
      const Vec2 a = s.centerline[k], b = s.centerline[k + 1];
      const Vec2 ab = b - a;
      const double len2 = std::max(ab.squaredNorm(), 1e-12);
      const double reach = s.half_width_m + kRoadBand;
      const int ix0 = std::max(0, static_cast<int>((std::min(a.x(), b.x()) - reach - xmin) / kRoadCell));
      const int ix1 = std::min(nx - 1, static_cast<int>((std::max(a.x(), b.x()) + reach - xmin) / kRoadCell) + 1);
      const int iy0 = std::max(0, static_cast<int>((std::min(a.y(), b.y()) - reach - ymin) / kRoadCell));
      const int iy1 = std::min(ny - 1, static_cast<int>((std::max(a.y(), b.y()) + reach - ymin) / kRoadCell) + 1);
      for (int iy = iy0; iy <= iy1; ++iy)
        for (int ix = ix0; ix <= ix1; ++ix) {
          const Vec2 p(xmin + ix * kRoadCell, ymin + iy * kRoadCell);
          const double u = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
          const float e = static_cast<float>((p - (a + u * ab)).norm() - s.half_width_m);
          float& cell = r.at(ix, iy);
          cell = std::min(cell, e);
        }
    }
  return r;
}

// Arc-length access to a polyline, with a tangent smoothed over a few metres.
class Polyline {
 public:
  explicit Polyline(const std::vector<Vec2>& pts) : pts_(pts), s_(pts.size(), 0.0) {
    for (std::size_t i = 1; i < pts.size(); ++i) s_[i] = s_[i - 1] + (pts[i] - pts[i - 1]).norm();
  }
  double length() const { return s_.back(); }
  Vec2 at(double s) const {
    s = std::clamp(s, 0.0, length());
    const auto it = std::upper_bound(s_.begin(), s_.end(), s);
    std::size_t i = std::min<std::size_t>(std::max<std::ptrdiff_t>(it - s_.begin(), 1), pts_.size() - 1);
    const double seg = std::max(s_[i] - s_[i - 1], 1e-9);
    return pts_[i - 1] + (pts_[i] - pts_[i - 1]) * ((s - s_[i - 1]) / seg);
  }
  Vec2 tangent(double s) const {
    Vec2 t = at(s + 3.0) - at(s - 3.0);
    if (t.norm() < 1e-9) t = pts_.back() - pts_.front();
    return t.normalized();
  }

 private:
  std::vector<Vec2> pts_;
  std::vector<double> s_;
};

enum class Zone { buildings, park, parking };

class Placer {
 public:
  Placer(World& world, std::uint64_t seed, CityStats& stats)
      : w_(world), seed_(seed), stats_(stats) {}

  Zone zone_at(const Vec2& p) const {
    const auto cx = static_cast<std::int64_t>(std::floor(p.x() / 75.0));
    const auto cy = static_cast<std::int64_t>(std::floor(p.y() / 75.0));
    const double u = static_cast<double>(hash_combine(hash_combine(seed_, cx * 73856093LL), cy) >> 11) * 0x1.0p-53;
    return u < 0.76 ? Zone::buildings : (u < 0.88 ? Zone::park : Zone::parking);
  }
  double edge(const Vec2& p) const { return w_.road_edge_distance.sample(p.x(), p.y()); }
  double ground(const Vec2& p) const { return w_.ground_height(p.x(), p.y()); }

  // A box's footprint keeps at least min_edge_m from every road edge (sampled every metre).
  bool footprint_clear(const Vec2& c, const Vec2& t, double half_along, double half_across,
                       double min_edge_m) const {
    const Vec2 n(-t.y(), t.x());
    const int na = std::max(2, static_cast<int>(2 * half_along) + 1);
    const int nb = std::max(2, static_cast<int>(2 * half_across) + 1);
    for (int i = 0; i <= na; ++i)
      for (int j = 0; j <= nb; ++j) {
        if (i != 0 && i != na && j != 0 && j != nb) continue;
        const Vec2 p = c + t * (half_along * (2.0 * i / na - 1)) + n * (half_across * (2.0 * j / nb - 1));
        if (edge(p) < min_edge_m) return false;
      }
    return true;
  }

  void add_box(const Vec2& c, const Vec2& t, double half_along, double half_across, double z0,
               double z1, SurfaceKind kind, float refl, float pass_prob = 0) {
    Primitive p = make_box(c.x(), c.y(), std::atan2(t.y(), t.x()), half_along, half_across, z0, z1, kind, refl);
    p.pass_prob = pass_prob;
    w_.primitives.push_back(p);
  }

  void building(Rng& rng, const Vec2& front_mid, const Vec2& t, const Vec2& n, double width,
                double min_edge) {
    double depth = rng.uniform(8, 22);
    const double h_pick = rng.uniform();
    const double height = h_pick < 0.55 ? rng.uniform(4, 12) : (h_pick < 0.85 ? rng.uniform(12, 24) : rng.uniform(24, 40));
    Vec2 ta = t;
    if (rng.chance(0.15)) {  // some buildings do not follow the street line
      const double a = rng.uniform(-0.17, 0.17);
      ta = Vec2(std::cos(a) * t.x() - std::sin(a) * t.y(), std::sin(a) * t.x() + std::cos(a) * t.y());
    }
    const Vec2 na = n.dot(Vec2(-ta.y(), ta.x())) > 0 ? Vec2(-ta.y(), ta.x()) : Vec2(ta.y(), -ta.x());
    // Near corners and on small blocks the lot is smaller than planned: shrink to fit.
    int tries = 0;
    while (!footprint_clear(front_mid + na * (depth / 2), ta, width / 2, depth / 2, min_edge)) {
      if (++tries > 3) return;
      width *= 0.7;
      depth *= 0.75;
      if (width < 5) return;
    }
    const Vec2 center = front_mid + na * (depth / 2);
    const double base = ground(center) - 3.0, top = ground(center) + height;
    const float refl = static_cast<float>(rng.uniform(0.15, 0.55));
    const double variant = rng.uniform();
    if (variant < 0.15 && width > 12) {
      // Stepped facade: two halves with fronts 1-3 m apart (a recess and two vertical edges).
      const double shift = rng.uniform(1, 3);
      for (int side = -1; side <= 1; side += 2) {
        const Vec2 c = center + ta * (side * width / 4) + na * (side > 0 ? shift / 2 : 0);
        const double d = side > 0 ? depth - shift : depth;
        add_box(c, ta, width / 4, d / 2, base, top - (side > 0 ? rng.uniform(0, 3) : 0), SurfaceKind::building, refl);
      }
    } else {
      add_box(center, ta, width / 2, depth / 2, base, top, SurfaceKind::building, refl);
    }
    if (variant >= 0.15 && variant < 0.35) {
      // L-shape: a wing reaching back from one side.
      const double wing_w = width * rng.uniform(0.3, 0.6), wing_d = rng.uniform(6, 16);
      const double side = rng.chance(0.5) ? 1 : -1;
      const Vec2 c = center + ta * (side * (width - wing_w) / 2) + na * (depth / 2 + wing_d / 2);
      if (footprint_clear(c, ta, wing_w / 2, wing_d / 2, min_edge))
        add_box(c, ta, wing_w / 2, wing_d / 2, base, ground(center) + height * rng.uniform(0.5, 1.0), SurfaceKind::building, refl);
    } else if (variant >= 0.35 && variant < 0.5 && height > 8) {
      // Setback upper storeys.
      const double inset = rng.uniform(2, 4), side_inset = rng.uniform(0.5, 3);
      if (width > 2 * side_inset + 3 && depth > inset + 3)
        add_box(center + na * (inset / 2), ta, width / 2 - side_inset, (depth - inset) / 2, top - 1,
                top + rng.uniform(3, 12), SurfaceKind::building, refl);
    }
    if (rng.chance(0.3)) {
      // Pillars, porches or bay windows standing out of the facade.
      const int count = rng.uniform_int(1, 3);
      for (int i = 0; i < count; ++i) {
        const double along = rng.uniform(-width / 2 + 1, width / 2 - 1), out = rng.uniform(0.4, 1.2);
        const Vec2 c = front_mid + ta * along - na * (out / 2);
        const double h = rng.chance(0.5) ? rng.uniform(2.5, 4) : height;
        if (footprint_clear(c, ta, 0.5, out / 2, min_edge - 1.3))
          add_box(c, ta, rng.uniform(0.3, 0.8), out / 2, base, ground(c) + h, SurfaceKind::building, refl);
      }
    }
    ++stats_.buildings;
  }

  void tree(Rng& rng, const Vec2& p) {
    const double g = ground(p), trunk_h = rng.uniform(2.2, 3.5);
    const double rxy = rng.uniform(1.5, 3.5), rz = rng.uniform(1.5, 3.0);
    // One draw per statement (see rng.hpp); this order keeps the worlds of earlier versions.
    const float trunk_refl = static_cast<float>(rng.uniform(0.25, 0.4));
    const double trunk_r = rng.uniform(0.12, 0.3);
    w_.primitives.push_back(make_cylinder(p.x(), p.y(), trunk_r, g - 1, g + trunk_h + 1.5 * rz,
                                          SurfaceKind::trunk, trunk_refl));
    const float free_path = static_cast<float>(rng.uniform(0.5, 1.5));
    const float crown_refl = static_cast<float>(rng.uniform(0.35, 0.6));
    const double dy = rng.uniform(-0.3, 0.3);
    const double dx = rng.uniform(-0.3, 0.3);
    w_.primitives.push_back(make_ellipsoid(p.x() + dx, p.y() + dy, g + trunk_h + rz, rxy, rz,
                                           SurfaceKind::vegetation, crown_refl, free_path));
    ++stats_.trees;
  }

  void car(Rng& rng, const Vec2& c, const Vec2& t) {
    const double g = ground(c);
    const float refl = static_cast<float>(rng.uniform(0.1, 0.8));
    if (rng.chance(0.12)) {  // van or small truck
      const double len = rng.uniform(5, 6.5);
      add_box(c, t, len / 2, 1.0, g + 0.35, g + rng.uniform(2.1, 2.7), SurfaceKind::car, refl);
    } else {
      const double len = rng.uniform(3.9, 4.9), half_w = rng.uniform(0.85, 0.95);
      add_box(c, t, len / 2, half_w, g + 0.3, g + rng.uniform(0.85, 1.0), SurfaceKind::car, refl);
      const double cabin_top = g + rng.uniform(1.4, 1.6);
      const double cabin_half_len = len * rng.uniform(0.24, 0.3);
      add_box(c - t * 0.2, t, cabin_half_len, half_w - 0.08, g + 0.9, cabin_top, SurfaceKind::car, refl);
    }
    // Wheels: the gap under the body is what a low beam sees.
    const Vec2 n(-t.y(), t.x());
    for (int a = -1; a <= 1; a += 2)
      for (int b = -1; b <= 1; b += 2)
        add_box(c + t * (a * 1.35) + n * (b * 0.75), t, 0.32, 0.1, g - 0.2, g + 0.6, SurfaceKind::car, 0.05f);
    ++stats_.cars;
  }

  void pole(Rng& rng, const Vec2& p, const Vec2& toward_road) {
    const double g = ground(p), h = rng.uniform(6, 9);
    w_.primitives.push_back(make_cylinder(p.x(), p.y(), rng.uniform(0.08, 0.14), g - 1, g + h, SurfaceKind::pole, 0.35f));
    add_box(p + toward_road * 0.9, toward_road, 0.9, 0.06, g + h - 0.15, g + h, SurfaceKind::pole, 0.35f);
    ++stats_.poles;
  }

  void sign(Rng& rng, const Vec2& p, const Vec2& t) {
    const double g = ground(p), h = rng.uniform(2.2, 3.0);
    w_.primitives.push_back(make_cylinder(p.x(), p.y(), 0.035, g - 1, g + h, SurfaceKind::pole, 0.35f));
    const double plate_bottom = g + h - rng.uniform(0.5, 0.8);
    const double plate_half_w = rng.uniform(0.3, 0.45);
    add_box(p, t, plate_half_w, 0.02, plate_bottom, g + h + 0.05, SurfaceKind::sign, 0.9f);
    ++stats_.signs;
  }

  void street(const Street& s, Rng& rng) {
    const Polyline line(s.centerline);
    const double L = line.length();
    for (int side = -1; side <= 1; side += 2) {
      auto frame = [&](double u, Vec2* p, Vec2* t, Vec2* n) {
        *t = line.tangent(u);
        *n = Vec2(-t->y(), t->x()) * side;  // away from the road, on this side
        *p = line.at(u);
      };
      Vec2 p, t, n;
      const double front = s.half_width_m + s.sidewalk_m + s.extra_setback_m;
      const double min_edge = s.sidewalk_m + s.extra_setback_m - 0.05;
      // Lots along the frontage.
      for (double u = rng.uniform(0, 8); u < L;) {
        const double width = rng.uniform(8, 28);
        frame(u + width / 2, &p, &t, &n);
        const Zone zone = zone_at(p + n * (front + 15));
        const double setback = rng.chance(0.5) ? 0.0 : rng.uniform(0.5, 5);
        const Vec2 front_mid = p + n * (front + setback);
        if (zone == Zone::buildings) {
          if (rng.chance(0.1)) {  // walled yard with a house at the back
            if (footprint_clear(front_mid + n * 0.15, t, width / 2 - 1, 0.15, min_edge))
              add_box(front_mid + n * 0.15 + t * 1.0, t, width / 2 - 2, 0.15, ground(front_mid) - 1,
                      ground(front_mid) + rng.uniform(1.5, 2.5), SurfaceKind::wall, 0.3f);
            building(rng, front_mid + n * rng.uniform(8, 14), t, n, width * 0.6, min_edge);
          } else {
            building(rng, front_mid, t, n, width, min_edge);
          }
        } else if (zone == Zone::park) {
          if (rng.chance(0.5) && footprint_clear(p + n * front, t, width / 2, 0.05, min_edge)) {
            add_box(p + n * front, t, width / 2 - 0.5, 0.03, ground(p + n * front) - 0.5,
                    ground(p + n * front) + rng.uniform(1.1, 1.8), SurfaceKind::fence, 0.3f, 0.6f);
            ++stats_.fences;
          }
          const int trees = static_cast<int>(width * 20 / 70) + rng.uniform_int(0, 2);
          for (int i = 0; i < trees; ++i) {
            const double out = front + rng.uniform(2, 25);
            const double along = rng.uniform(-width / 2, width / 2);
            const Vec2 q = p + t * along + n * out;
            if (edge(q) > min_edge + 1.5) tree(rng, q);
          }
        } else {
          const int rows = rng.uniform_int(1, 2);
          for (int r = 0; r < rows; ++r)
            for (double a = -width / 2 + 1.3; a < width / 2 - 1.3; a += 2.6) {
              const Vec2 c = p + t * a + n * (front + 3 + r * 5.5);
              if (rng.chance(0.65) && footprint_clear(c, n, 2.5, 1.0, min_edge)) car(rng, c, n);
            }
          const Vec2 q = p + n * (front + 1);
          if (rng.chance(0.5) && edge(q) > min_edge) pole(rng, q, -n);
        }
        u += width + (rng.chance(0.5) ? rng.uniform(0, 1) : rng.uniform(2, 9));
      }
      // Lamp posts along the curb.
      for (double u = rng.uniform(5, 20); u < L; u += rng.uniform(25, 40)) {
        frame(u, &p, &t, &n);
        const Vec2 q = p + n * (s.half_width_m + 0.5);
        if (edge(q) > 0.3 && edge(q) < s.sidewalk_m) pole(rng, q, -n);
      }
      // Street trees.
      if (s.tree_lined)
        for (double u = rng.uniform(2, 8); u < L; u += rng.uniform(7, 13)) {
          frame(u, &p, &t, &n);
          const Vec2 q = p + n * (s.half_width_m + s.sidewalk_m * 0.55);
          if (edge(q) > 0.8 && edge(q) < s.sidewalk_m) tree(rng, q);
        }
      // Signs and small street furniture (bins, bollards, hydrants).
      for (double u = rng.uniform(5, 30); u < L; u += rng.uniform(15, 45)) {
        frame(u, &p, &t, &n);
        const Vec2 q = p + n * (s.half_width_m + rng.uniform(0.3, 1.2));
        if (edge(q) < 0.25 || edge(q) > s.sidewalk_m) continue;
        if (rng.chance(0.4)) {
          sign(rng, q, t);
        } else {
          const double g = ground(q), h = rng.uniform(0.4, 1.2);
          if (rng.chance(0.5)) {
            w_.primitives.push_back(make_cylinder(q.x(), q.y(), rng.uniform(0.1, 0.3), g - 0.5, g + h, SurfaceKind::pole, 0.3f));
          } else {
            const double half_y = rng.uniform(0.25, 0.4);
            const double half_x = rng.uniform(0.25, 0.5);
            add_box(q, t, half_x, half_y, g - 0.5, g + h, SurfaceKind::wall, 0.25f);
          }
        }
      }
      // Parked cars along the curb, kept clear of intersections and lanes.
      if (s.parking)
        for (double u = rng.uniform(3, 10); u < L; u += rng.uniform(5.5, 8.5)) {
          if (rng.chance(0.35)) continue;
          if (u < 25 || u > L - 25) continue;  // no parking near intersections (turning cars)
          frame(u, &p, &t, &n);
          const Vec2 c = p + n * (s.half_width_m - 1.15);
          if (edge(c) > -0.6 || edge(c) < -1.7) continue;
          bool clear = true;
          for (int a = -1; a <= 1 && clear; a += 2)
            for (int b = -1; b <= 1 && clear; b += 2)
              clear = edge(c + t * (a * 3.0) + n * (b * 1.0)) < -0.1 && edge(c + t * (a * 3.0) - n * 1.0) > -2.3;
          if (clear) car(rng, c, t * (rng.chance(0.5) ? 1.0 : -1.0));
        }
    }
  }

 private:
  World& w_;
  std::uint64_t seed_;
  CityStats& stats_;
};

}  // namespace

World build_city(const std::vector<Street>& streets, Raster2D terrain, std::uint64_t seed,
                 CityStats* stats) {
  World world;
  world.road_edge_distance = rasterize_roads(streets, terrain);
  world.terrain_m = std::move(terrain);
  CityStats local;
  Placer placer(world, seed, stats ? *stats : local);
  for (std::size_t i = 0; i < streets.size(); ++i) {
    Rng rng(hash_combine(seed, 0x5EED0000ULL + i));
    placer.street(streets[i], rng);
  }
  world.build_index(4.0);
  return world;
}

}  // namespace scfloam::sim
