// Procedural facades: every parameter is drawn from the primitive's index, so the pattern
// costs no memory and the same wall always looks the same from every viewpoint.
#include "scfloam/sim/facade.hpp"

#include <algorithm>
#include <cmath>

#include "scfloam/sim/rng.hpp"

namespace scfloam::sim {
namespace {

struct FacadeStyle {
  bool blank = false;            // warehouses, blind walls
  double storey_m = 3.2;
  double bay_m = 3.0, window_w_m = 1.5, sill_m = 0.9, window_h_m = 1.5, recess_m = 0.2;
  bool curtain_wall = false;     // office glass: panes between thin mullions
  bool shop_front = false;       // ground storey: large recessed shop windows
  double shop_recess_m = 0.2;
  bool ledges = false;           // a band along every floor line
  double ledge_out_m = 0.15, ledge_h_m = 0.3;
};

FacadeStyle style_of(std::uint32_t index) {
  Rng rng(hash_combine(0xFACADEULL, index));
  FacadeStyle s;
  s.storey_m = rng.uniform(2.9, 3.8);
  const double kind = rng.uniform();
  if (kind < 0.12) {
    s.blank = true;
  } else if (kind < 0.27) {
    s.curtain_wall = true;
    s.bay_m = rng.uniform(1.2, 1.8);
    s.window_w_m = s.bay_m - 0.12;
    s.sill_m = 0.1;
    s.window_h_m = s.storey_m - 0.25;
    s.recess_m = rng.uniform(0.03, 0.08);
  } else {
    s.bay_m = rng.uniform(2.4, 4.2);
    s.window_w_m = s.bay_m * rng.uniform(0.35, 0.65);
    s.sill_m = rng.uniform(0.8, 1.0);
    s.window_h_m = rng.uniform(1.2, std::min(2.0, s.storey_m - s.sill_m - 0.3));
    s.recess_m = rng.uniform(0.1, 0.3);
  }
  s.shop_front = !s.blank && rng.chance(0.4);
  s.shop_recess_m = rng.uniform(0.1, 0.3);
  s.ledges = !s.curtain_wall && rng.chance(0.4);
  s.ledge_out_m = rng.uniform(0.1, 0.25);
  s.ledge_h_m = rng.uniform(0.2, 0.45);
  return s;
}

double ray_uniform(std::uint64_t ray_seed, std::uint64_t salt) {
  return static_cast<double>(hash_combine(ray_seed, salt) >> 11) * 0x1.0p-53;
}

}  // namespace

bool refine_facade_hit(const Primitive& p, std::uint32_t index, const Eigen::Vector3d& o,
                       const Eigen::Vector3d& d, std::uint64_t ray_seed, const FacadeConfig& config,
                       RayHit* hit) {
  const Eigen::Vector3d n = hit->normal;  // horizontal, facing the ray = out of the wall
  const Eigen::Vector3d x_axis(p.cos_yaw, p.sin_yaw, 0), y_axis(-p.sin_yaw, p.cos_yaw, 0);
  const bool x_face = std::abs(n.dot(x_axis)) > 0.7;
  const Eigen::Vector3d u_axis = x_face ? y_axis : x_axis;
  const double half_face = x_face ? p.hy : p.hx;
  if (half_face < 1.5 || p.z1 - p.z0 < 5) return true;  // pillars, porches: plain
  const FacadeStyle s = style_of(index);
  if (s.blank) return true;

  const Eigen::Vector3d hit_point = o + hit->range_m * d;
  const double u = (hit_point - Eigen::Vector3d(p.cx, p.cy, hit_point.z())).dot(u_axis) + half_face;
  const double z = hit_point.z();
  const double du = d.dot(u_axis), dz = d.z(), dw = std::max(1e-6, -d.dot(n));
  const double ground_z = p.z0 + 3.0;  // building boxes reach 3 m under the ground
  const double height = z - ground_z;
  if (height < 0) return true;
  const int storey = static_cast<int>(height / s.storey_m);

  // A ledge along the floor line above or below: the ray may meet it before the wall.
  if (s.ledges && storey >= 1) {
    for (int k : {storey, storey + 1}) {
      const double zb = ground_z + k * s.storey_m - s.ledge_h_m / 2, zt = zb + s.ledge_h_m;
      if (zt > p.z1 - 0.3) continue;
      const double s_front = -s.ledge_out_m / dw;  // along the ray, before the wall hit
      double s_lo = -1e9, s_hi = 1e9;
      if (std::abs(dz) > 1e-9) {
        s_lo = std::min((zb - z) / dz, (zt - z) / dz);
        s_hi = std::max((zb - z) / dz, (zt - z) / dz);
      } else if (z < zb || z > zt) {
        continue;
      }
      const double s_in = std::max(s_front, s_lo), s_out = std::min(0.0, s_hi);
      if (s_in <= s_out) {
        hit->range_m += s_in;
        hit->normal = s_in == s_front ? n : Eigen::Vector3d(0, 0, dz < 0 ? 1 : -1);
        return true;
      }
    }
  }

  // The opening at the hit, if any: [ua, ub] x [za, zb], recessed by depth.
  const double margin = 0.8, span = 2 * half_face - 2 * margin;
  if (u < margin || u > 2 * half_face - margin) return true;
  double ua, ub, za, zb, depth;
  const double storey_z = ground_z + storey * s.storey_m;
  if (storey == 0 && s.shop_front) {
    const double bay = std::max(3.0, s.bay_m * 2);
    const int bays = static_cast<int>(span / bay);
    if (bays < 1) return true;
    const double start = margin + (span - bays * bay) / 2;
    const int b = static_cast<int>(std::floor((u - start) / bay));
    if (b < 0 || b >= bays) return true;
    ua = start + b * bay + 0.2;
    ub = start + (b + 1) * bay - 0.2;
    za = storey_z + 0.4;
    zb = storey_z + std::min(3.0, s.storey_m - 0.3);
    depth = s.shop_recess_m;
  } else {
    const int bays = static_cast<int>(span / s.bay_m);
    if (bays < 1) return true;
    const double start = margin + (span - bays * s.bay_m) / 2;
    const int b = static_cast<int>(std::floor((u - start) / s.bay_m));
    if (b < 0 || b >= bays) return true;
    const double center = start + (b + 0.5) * s.bay_m;
    ua = center - s.window_w_m / 2;
    ub = center + s.window_w_m / 2;
    za = storey_z + s.sill_m;
    zb = za + s.window_h_m;
    depth = s.recess_m;
  }
  if (u < ua || u > ub || z < za || z > zb || zb > p.z1 - 0.6) return true;

  // Inside the opening: the ray ends on the pane or on a reveal (jamb, sill, head).
  double s_end = depth / dw;
  Eigen::Vector3d normal = n;
  bool pane = true;
  if (std::abs(du) > 1e-9) {
    const double s_u = ((du > 0 ? ub : ua) - u) / du;
    if (s_u < s_end) s_end = s_u, normal = du > 0 ? Eigen::Vector3d(-u_axis) : u_axis, pane = false;
  }
  if (std::abs(dz) > 1e-9) {
    const double s_z = ((dz > 0 ? zb : za) - z) / dz;
    if (s_z < s_end) s_end = s_z, normal = Eigen::Vector3d(0, 0, dz > 0 ? -1 : 1), pane = false;
  }
  hit->range_m += s_end;
  hit->normal = normal;
  if (!pane) return true;
  const double r = ray_uniform(ray_seed, 0x61A55ULL + index);
  if (r < config.glass_no_return_prob) return false;
  if (r < config.glass_no_return_prob + config.glass_pass_prob) {
    // Into the room: furniture, blinds or the back wall 0.5-8 m behind the pane.
    const double room = 0.5 + 7.5 * ray_uniform(ray_seed, 0x7005ULL + index);
    hit->range_m += room / dw;
    hit->reflectance = static_cast<float>(0.15 + 0.4 * ray_uniform(ray_seed, 0x7006ULL + index));
    hit->normal = n;
    return true;
  }
  hit->reflectance = config.glass_reflectance;
  return true;
}

}  // namespace scfloam::sim
