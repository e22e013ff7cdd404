// Ray casting against the simulated world: a marched height field for the ground and
// curbs, and a 2D uniform grid (Amanatides-Woo DDA) over the solid primitives.
#include "scfloam/sim/world.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "scfloam/sim/facade.hpp"
#include "scfloam/sim/rng.hpp"

namespace scfloam::sim {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
// Uniform [0,1) number for (ray, primitive): independent of traversal order.
double ray_uniform(std::uint64_t ray_seed, std::uint32_t index) {
  return static_cast<double>(hash_combine(ray_seed, index) >> 11) * 0x1.0p-53;
}
}  // namespace

const char* surface_kind_name(SurfaceKind kind) {
  switch (kind) {
    case SurfaceKind::road: return "road";
    case SurfaceKind::sidewalk: return "sidewalk";
    case SurfaceKind::curb: return "curb";
    case SurfaceKind::building: return "building";
    case SurfaceKind::vegetation: return "vegetation";
    case SurfaceKind::trunk: return "trunk";
    case SurfaceKind::car: return "car";
    case SurfaceKind::pole: return "pole";
    case SurfaceKind::sign: return "sign";
    case SurfaceKind::fence: return "fence";
    case SurfaceKind::wall: return "wall";
    case SurfaceKind::person: return "person";
  }
  return "unknown";
}

void Raster2D::reset(double x0_m, double y0_m, double cell_size_m, int cols, int rows,
                     float fill) {
  x0 = x0_m;
  y0 = y0_m;
  cell_m = cell_size_m;
  nx = cols;
  ny = rows;
  values.assign(static_cast<std::size_t>(cols) * rows, fill);
}

Eigen::Vector2d Raster2D::gradient(double x, double y) const {
  double fx = (x - x0) / cell_m, fy = (y - y0) / cell_m;
  fx = std::clamp(fx, 0.0, nx - 1.000001);
  fy = std::clamp(fy, 0.0, ny - 1.000001);
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  const double ax = fx - ix, ay = fy - iy;
  const float* row0 = &values[static_cast<std::size_t>(iy) * nx + ix];
  const float* row1 = row0 + nx;
  const double gx = ((1 - ay) * (row0[1] - row0[0]) + ay * (row1[1] - row1[0])) / cell_m;
  const double gy = ((1 - ax) * (row1[0] - row0[0]) + ax * (row1[1] - row0[1])) / cell_m;
  return {gx, gy};
}

void Primitive::bounds(double& xmin, double& ymin, double& xmax, double& ymax) const {
  double ex = hx, ey = hx;
  if (shape == Shape::box) {
    ex = std::abs(cos_yaw) * hx + std::abs(sin_yaw) * hy;
    ey = std::abs(sin_yaw) * hx + std::abs(cos_yaw) * hy;
  }
  xmin = cx - ex;
  xmax = cx + ex;
  ymin = cy - ey;
  ymax = cy + ey;
}

Primitive make_box(double cx, double cy, double yaw_rad, double half_x, double half_y,
                   double z_bottom, double z_top, SurfaceKind kind, float reflectance) {
  Primitive p;
  p.shape = Primitive::Shape::box;
  p.cx = cx;
  p.cy = cy;
  p.cos_yaw = std::cos(yaw_rad);
  p.sin_yaw = std::sin(yaw_rad);
  p.hx = half_x;
  p.hy = half_y;
  p.z0 = z_bottom;
  p.z1 = z_top;
  p.kind = kind;
  p.reflectance = reflectance;
  return p;
}

Primitive make_cylinder(double cx, double cy, double radius, double z_bottom, double z_top,
                        SurfaceKind kind, float reflectance) {
  Primitive p;
  p.shape = Primitive::Shape::cylinder;
  p.cx = cx;
  p.cy = cy;
  p.hx = p.hy = radius;
  p.z0 = z_bottom;
  p.z1 = z_top;
  p.kind = kind;
  p.reflectance = reflectance;
  return p;
}

Primitive make_ellipsoid(double cx, double cy, double cz, double radius_xy, double radius_z,
                         SurfaceKind kind, float reflectance, float mean_free_path_m) {
  Primitive p;
  p.shape = Primitive::Shape::ellipsoid;
  p.cx = cx;
  p.cy = cy;
  p.hx = p.hy = radius_xy;
  p.z0 = cz;
  p.z1 = radius_z;
  p.kind = kind;
  p.reflectance = reflectance;
  p.mean_free_path_m = mean_free_path_m;
  return p;
}

void World::build_index(double cell_m) {
  double xmin = kInf, ymin = kInf, xmax = -kInf, ymax = -kInf;
  max_object_z_ = -kInf;
  for (const auto& p : primitives) {
    double a, b, c, d;
    p.bounds(a, b, c, d);
    xmin = std::min(xmin, a);
    ymin = std::min(ymin, b);
    xmax = std::max(xmax, c);
    ymax = std::max(ymax, d);
    const double top = p.shape == Primitive::Shape::ellipsoid ? p.z0 + p.z1 : p.z1;
    max_object_z_ = std::max(max_object_z_, top);
  }
  if (primitives.empty()) {
    xmin = ymin = 0;
    xmax = ymax = 1;
    max_object_z_ = 0;
  }
  grid_cell_m_ = cell_m;
  grid_x0_ = xmin - cell_m;
  grid_y0_ = ymin - cell_m;
  grid_nx_ = static_cast<int>(std::ceil((xmax - grid_x0_) / cell_m)) + 1;
  grid_ny_ = static_cast<int>(std::ceil((ymax - grid_y0_) / cell_m)) + 1;
  const std::size_t cells = static_cast<std::size_t>(grid_nx_) * grid_ny_;
  std::vector<std::uint32_t> counts(cells + 1, 0);
  auto for_cells = [&](const Primitive& p, auto&& fn) {
    double a, b, c, d;
    p.bounds(a, b, c, d);
    const int ix0 = static_cast<int>((a - grid_x0_) / cell_m), ix1 = static_cast<int>((c - grid_x0_) / cell_m);
    const int iy0 = static_cast<int>((b - grid_y0_) / cell_m), iy1 = static_cast<int>((d - grid_y0_) / cell_m);
    for (int iy = iy0; iy <= iy1; ++iy)
      for (int ix = ix0; ix <= ix1; ++ix) fn(static_cast<std::size_t>(iy) * grid_nx_ + ix);
  };
  for (const auto& p : primitives) for_cells(p, [&](std::size_t c) { ++counts[c + 1]; });
  for (std::size_t c = 0; c < cells; ++c) counts[c + 1] += counts[c];
  cell_start_ = counts;
  cell_items_.assign(counts[cells], 0);
  std::vector<std::uint32_t> fill(counts.begin(), counts.end() - 1);
  for (std::uint32_t i = 0; i < primitives.size(); ++i)
    for_cells(primitives[i], [&](std::size_t c) { cell_items_[fill[c]++] = i; });

  // Local slope bounds: max slope per 32 m block, dilated to the 3x3 neighbourhood.
  const Raster2D& T = terrain_m;
  const int bx = static_cast<int>(std::ceil((T.nx - 1) * T.cell_m / kSlopeBlock)) + 1;
  const int by = static_cast<int>(std::ceil((T.ny - 1) * T.cell_m / kSlopeBlock)) + 1;
  Raster2D block_max;
  block_max.reset(T.x0, T.y0, kSlopeBlock, bx, by, 0.0f);
  for (int iy = 0; iy + 1 < T.ny; ++iy)
    for (int ix = 0; ix + 1 < T.nx; ++ix) {
      const double sx = std::abs(T.at(ix + 1, iy) - T.at(ix, iy)), sy = std::abs(T.at(ix, iy + 1) - T.at(ix, iy));
      const float slope = static_cast<float>(std::sqrt(sx * sx + sy * sy) / T.cell_m);
      // A terrain cell can touch two blocks: credit both corners' blocks.
      for (int cy = iy; cy <= iy + 1; ++cy)
        for (int cx = ix; cx <= ix + 1; ++cx) {
          float& b = block_max.at(std::min(bx - 1, static_cast<int>(cx * T.cell_m / kSlopeBlock)),
                                  std::min(by - 1, static_cast<int>(cy * T.cell_m / kSlopeBlock)));
          b = std::max(b, slope);
        }
    }
  slope_bound_ = block_max;
  for (int iy = 0; iy < by; ++iy)
    for (int ix = 0; ix < bx; ++ix) {
      float m = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int jx = std::clamp(ix + dx, 0, bx - 1), jy = std::clamp(iy + dy, 0, by - 1);
          m = std::max(m, block_max.at(jx, jy));
        }
      slope_bound_.at(ix, iy) = 1.2f * m + 0.01f;
    }
}

double World::ground_height(double x, double y) const {
  return terrain_m.sample(x, y) + (road_edge_distance.sample(x, y) > 0 ? curb_height_m : 0.0);
}

bool World::cast_ground(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_max,
                        RayHit* hit) const {
  // gap(t) = ray height above the ground; `raised` tells whether the ground there is a sidewalk.
  auto gap = [&](double t, bool* raised) {
    const double x = o.x() + t * d.x(), y = o.y() + t * d.y();
    *raised = road_edge_distance.sample(x, y) > 0;
    return o.z() + t * d.z() - terrain_m.sample(x, y) - (*raised ? curb_height_m : 0.0);
  };
  const double horizontal = std::sqrt(d.x() * d.x() + d.y() * d.y());
  // A step may reach at most one slope block away (the bound covers the 3x3 blocks).
  const double max_step = horizontal > 1e-9 ? kSlopeBlock / horizontal : 1e9;
  constexpr double kMinStep = 0.8;  // sidewalks are wider than this: no curb is stepped over
  bool raised = false;
  double t = 0, g = gap(0, &raised);
  if (g <= 0) return false;
  while (t < t_max) {
    // Per unit of t the gap can shrink at most this fast, plus one curb step over a road.
    const double x = o.x() + t * d.x(), y = o.y() + t * d.y();
    const double slope = slope_bound_.values[std::min<std::size_t>(
        slope_bound_.values.size() - 1,
        static_cast<std::size_t>(std::clamp(static_cast<int>((y - slope_bound_.y0) / kSlopeBlock), 0, slope_bound_.ny - 1)) * slope_bound_.nx +
            std::clamp(static_cast<int>((x - slope_bound_.x0) / kSlopeBlock), 0, slope_bound_.nx - 1))];
    const double closing = std::max(1e-6, -d.z() + slope * horizontal);
    const double reserve = raised ? 0.0 : curb_height_m + 0.01;
    const double step = std::clamp((g - reserve) / closing, kMinStep, std::max(kMinStep, max_step));
    const double t_next = std::min(t + step, t_max);
    bool raised_next;
    const double g_next = gap(t_next, &raised_next);
    if (g_next <= 0) {
      // The crossing lies in [t, t_next] (at most kMinStep long): bisect to 2 cm, then
      // interpolate linearly over the smooth terrain.
      double lo = t, hi = t_next, g_lo = g, g_hi = g_next;
      bool raised_lo = raised, raised_hi = raised_next;
      while (hi - lo > 0.02) {
        const double mid = 0.5 * (lo + hi);
        bool raised_mid;
        const double g_mid = gap(mid, &raised_mid);
        if (g_mid > 0) {
          lo = mid, g_lo = g_mid, raised_lo = raised_mid;
        } else {
          hi = mid, g_hi = g_mid, raised_hi = raised_mid;
        }
      }
      const double th = raised_lo == raised_hi ? lo + (hi - lo) * g_lo / (g_lo - g_hi) : 0.5 * (lo + hi);
      const double x = o.x() + th * d.x(), y = o.y() + th * d.y();
      hit->range_m = th;
      if (!raised_lo && raised_hi) {
        // Entered the raised side below its top: the vertical curb face.
        Eigen::Vector2d g2 = -road_edge_distance.gradient(x, y);
        if (g2.squaredNorm() < 1e-12) g2 = -Eigen::Vector2d(d.x(), d.y());
        g2.normalize();
        hit->normal = Eigen::Vector3d(g2.x(), g2.y(), 0);
        hit->kind = SurfaceKind::curb;
        hit->reflectance = curb_reflectance;
      } else {
        const Eigen::Vector2d grad = terrain_m.gradient(x, y);
        hit->normal = Eigen::Vector3d(-grad.x(), -grad.y(), 1).normalized();
        hit->kind = raised_hi ? SurfaceKind::sidewalk : SurfaceKind::road;
        hit->reflectance = raised_hi ? sidewalk_reflectance : road_reflectance;
      }
      return true;
    }
    t = t_next;
    g = g_next;
    raised = raised_next;
    if (d.z() >= 0 && g > 200) return false;  // climbing away from the ground
  }
  return false;
}

bool World::hit_primitive(const Primitive& p, std::uint32_t index, const Eigen::Vector3d& o,
                          const Eigen::Vector3d& d, double t_max, std::uint64_t ray_seed,
                          double* t_out, Eigen::Vector3d* normal) const {
  const double px = o.x() - p.cx, py = o.y() - p.cy;
  switch (p.shape) {
    case Primitive::Shape::box: {
      const double lo[3] = {-p.hx, -p.hy, p.z0}, hi[3] = {p.hx, p.hy, p.z1};
      const double lo_o[3] = {p.cos_yaw * px + p.sin_yaw * py, -p.sin_yaw * px + p.cos_yaw * py, o.z()};
      const double lo_d[3] = {p.cos_yaw * d.x() + p.sin_yaw * d.y(),
                              -p.sin_yaw * d.x() + p.cos_yaw * d.y(), d.z()};
      double t_near = -kInf, t_far = kInf;
      int axis = 0;
      for (int k = 0; k < 3; ++k) {
        if (std::abs(lo_d[k]) < 1e-12) {
          if (lo_o[k] < lo[k] || lo_o[k] > hi[k]) return false;
          continue;
        }
        double t1 = (lo[k] - lo_o[k]) / lo_d[k], t2 = (hi[k] - lo_o[k]) / lo_d[k];
        if (t1 > t2) std::swap(t1, t2);
        if (t1 > t_near) {
          t_near = t1;
          axis = k;
        }
        t_far = std::min(t_far, t2);
      }
      if (t_near > t_far || t_near <= 0 || t_near >= t_max) return false;
      if (p.pass_prob > 0 && ray_uniform(ray_seed, index) < p.pass_prob) return false;
      const double s = lo_d[axis] > 0 ? -1.0 : 1.0;
      if (axis == 0) *normal = Eigen::Vector3d(s * p.cos_yaw, s * p.sin_yaw, 0);
      else if (axis == 1) *normal = Eigen::Vector3d(-s * p.sin_yaw, s * p.cos_yaw, 0);
      else *normal = Eigen::Vector3d(0, 0, s);
      *t_out = t_near;
      return true;
    }
    case Primitive::Shape::cylinder: {
      const double r = p.hx;
      const double a = d.x() * d.x() + d.y() * d.y();
      if (a > 1e-12) {
        const double b = px * d.x() + py * d.y();
        const double c = px * px + py * py - r * r;
        const double disc = b * b - a * c;
        if (disc < 0) return false;
        const double t = (-b - std::sqrt(disc)) / a;
        if (t <= 0) return false;
        const double z = o.z() + t * d.z();
        if (t < t_max && z >= p.z0 && z <= p.z1) {
          *normal = Eigen::Vector3d((px + t * d.x()) / r, (py + t * d.y()) / r, 0);
          *t_out = t;
          return true;
        }
        if (z <= p.z1 || d.z() >= 0) return false;
      } else if (d.z() >= 0 || px * px + py * py > r * r) {
        return false;
      }
      const double tc = (p.z1 - o.z()) / d.z();  // top cap, ray coming down
      const double cx = px + tc * d.x(), cy = py + tc * d.y();
      if (tc <= 0 || tc >= t_max || cx * cx + cy * cy > r * r) return false;
      *normal = Eigen::Vector3d::UnitZ();
      *t_out = tc;
      return true;
    }
    case Primitive::Shape::ellipsoid: {
      const double k = p.hx / p.z1;  // squash z so the ellipsoid becomes a sphere
      const double qz = (o.z() - p.z0) * k, dz = d.z() * k;
      const double a = d.x() * d.x() + d.y() * d.y() + dz * dz;
      const double b = px * d.x() + py * d.y() + qz * dz;
      const double c = px * px + py * py + qz * qz - p.hx * p.hx;
      const double disc = b * b - a * c;
      if (disc < 0) return false;
      const double root = std::sqrt(disc);
      const double t_in = std::max((-b - root) / a, 0.0), t_exit = (-b + root) / a;
      if (t_exit <= 0 || t_in >= t_max) return false;
      double t = t_in;
      if (p.mean_free_path_m > 0) {
        // Foliage: the ray travels an exponentially distributed distance before it hits a leaf.
        t += -p.mean_free_path_m * std::log(1.0 - ray_uniform(ray_seed, index));
        if (t >= t_exit) return false;
      }
      if (t <= 0 || t >= t_max) return false;
      *normal = -d;
      *t_out = t;
      return true;
    }
  }
  return false;
}

bool World::cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_range_m,
                 std::uint64_t ray_seed, RayHit* hit) const {
  double best_t = max_range_m;
  bool found = cast_ground(o, d, max_range_m, hit);
  if (found) best_t = hit->range_m;
  if (cell_start_.empty()) return found;

  const double cs = grid_cell_m_;
  int ix = static_cast<int>(std::floor((o.x() - grid_x0_) / cs));
  int iy = static_cast<int>(std::floor((o.y() - grid_y0_) / cs));
  const int step_x = d.x() > 0 ? 1 : -1, step_y = d.y() > 0 ? 1 : -1;
  double t_next_x = std::abs(d.x()) > 1e-12
                        ? ((ix + (d.x() > 0 ? 1 : 0)) * cs + grid_x0_ - o.x()) / d.x() : kInf;
  double t_next_y = std::abs(d.y()) > 1e-12
                        ? ((iy + (d.y() > 0 ? 1 : 0)) * cs + grid_y0_ - o.y()) / d.y() : kInf;
  const double dt_x = std::abs(d.x()) > 1e-12 ? cs / std::abs(d.x()) : kInf;
  const double dt_y = std::abs(d.y()) > 1e-12 ? cs / std::abs(d.y()) : kInf;
  int best_index = -1;
  Eigen::Vector3d best_normal;
  double t_entry = 0;
  while (t_entry < best_t) {
    if (ix >= 0 && iy >= 0 && ix < grid_nx_ && iy < grid_ny_) {
      const std::size_t cell = static_cast<std::size_t>(iy) * grid_nx_ + ix;
      for (std::uint32_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
        const std::uint32_t index = cell_items_[k];
        double t;
        Eigen::Vector3d n;
        if (hit_primitive(primitives[index], index, o, d, best_t, ray_seed, &t, &n)) {
          best_t = t;
          best_index = static_cast<int>(index);
          best_normal = n;
        }
      }
    } else if ((ix < 0 && step_x < 0) || (iy < 0 && step_y < 0) ||
               (ix >= grid_nx_ && step_x > 0) || (iy >= grid_ny_ && step_y > 0)) {
      break;  // left the grid for good
    }
    const double t_exit = std::min(t_next_x, t_next_y);
    if (best_t <= t_exit) break;
    if (d.z() > 0 && o.z() + t_exit * d.z() > max_object_z_) break;
    t_entry = t_exit;
    if (t_next_x < t_next_y) {
      ix += step_x;
      t_next_x += dt_x;
    } else {
      iy += step_y;
      t_next_y += dt_y;
    }
  }
  if (best_index >= 0) {
    const Primitive& p = primitives[best_index];
    hit->range_m = best_t;
    hit->normal = best_normal;
    hit->kind = p.kind;
    hit->reflectance = p.reflectance;
    if (facade_detail && p.kind == SurfaceKind::building && p.shape == Primitive::Shape::box &&
        std::abs(best_normal.z()) < 0.5)
      return refine_facade_hit(p, static_cast<std::uint32_t>(best_index), o, d, ray_seed, facade, hit);
    return true;
  }
  return found;
}

}  // namespace scfloam::sim
