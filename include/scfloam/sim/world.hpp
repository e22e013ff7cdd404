// The simulated static world: a ground height field with raised sidewalks (curbs) and a
// set of solid primitives (oriented boxes, vertical cylinders, porous ellipsoids) indexed
// by a 2D uniform grid for fast ray casting (DDA traversal).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace scfloam::sim {

enum class SurfaceKind : std::uint8_t {
  road, sidewalk, curb, building, vegetation, trunk, car, pole, sign, fence, wall, person
};
const char* surface_kind_name(SurfaceKind kind);

// A regular 2D grid of samples read with bilinear interpolation (terrain heights,
// signed distances). Outside the grid it clamps to the border.
struct Raster2D {
  double x0 = 0, y0 = 0, cell_m = 1;
  int nx = 0, ny = 0;
  std::vector<float> values;  // row-major, index = iy * nx + ix
  void reset(double x0_m, double y0_m, double cell_size_m, int cols, int rows, float fill);
  float& at(int ix, int iy) { return values[static_cast<std::size_t>(iy) * nx + ix]; }
  float at(int ix, int iy) const { return values[static_cast<std::size_t>(iy) * nx + ix]; }
  double sample(double x, double y) const {
    double fx = (x - x0) / cell_m, fy = (y - y0) / cell_m;
    fx = fx < 0 ? 0 : (fx > nx - 1.000001 ? nx - 1.000001 : fx);
    fy = fy < 0 ? 0 : (fy > ny - 1.000001 ? ny - 1.000001 : fy);
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const double ax = fx - ix, ay = fy - iy;
    const float* row0 = &values[static_cast<std::size_t>(iy) * nx + ix];
    const float* row1 = row0 + nx;
    return (1 - ay) * ((1 - ax) * row0[0] + ax * row0[1]) + ay * ((1 - ax) * row1[0] + ax * row1[1]);
  }
  // Gradient (d/dx, d/dy) of the bilinear interpolant.
  Eigen::Vector2d gradient(double x, double y) const;
};

struct Primitive {
  enum class Shape : std::uint8_t { box, cylinder, ellipsoid };
  Shape shape = Shape::box;
  SurfaceKind kind = SurfaceKind::building;
  float reflectance = 0.3f;
  // Rays cross a porous primitive with this mean free path (foliage); 0 = solid.
  float mean_free_path_m = 0;
  // Probability that a ray passes a thin see-through primitive (mesh fence); 0 = opaque.
  float pass_prob = 0;
  double cx = 0, cy = 0;       // center of the footprint
  double cos_yaw = 1, sin_yaw = 0;
  double hx = 0, hy = 0;       // box half extents along its own x/y; cylinder: hx = radius
  double z0 = 0, z1 = 0;       // box/cylinder vertical extent; ellipsoid: center z = z0, rz = z1
  // Axis-aligned xy bounds, for the grid.
  void bounds(double& xmin, double& ymin, double& xmax, double& ymax) const;
};

Primitive make_box(double cx, double cy, double yaw_rad, double half_x, double half_y,
                   double z_bottom, double z_top, SurfaceKind kind, float reflectance);
Primitive make_cylinder(double cx, double cy, double radius, double z_bottom, double z_top,
                        SurfaceKind kind, float reflectance);
Primitive make_ellipsoid(double cx, double cy, double cz, double radius_xy, double radius_z,
                         SurfaceKind kind, float reflectance, float mean_free_path_m);

struct RayHit {
  double range_m = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, facing the ray
  SurfaceKind kind = SurfaceKind::road;
  float reflectance = 0;
};

// Glass in the facade detail (see facade.hpp).
struct FacadeConfig {
  double glass_no_return_prob = 0.25;  // a pane gives no return (specular reflection away)
  double glass_pass_prob = 0.35;       // the ray goes through and returns from the room
  float glass_reflectance = 0.08f;     // what a pane returns otherwise
};

class World {
 public:
  // Ground = terrain + curb_height_m where road_edge_distance > 0 (off the road).
  Raster2D terrain_m;           // ground height of the road surface
  Raster2D road_edge_distance;  // signed distance to the nearest road edge, < 0 on roads
  double curb_height_m = 0.15;
  // KITTI's HDL-64E reads asphalt at ~0.2-0.35 (median of real scans ~0.3).
  float road_reflectance = 0.28f, sidewalk_reflectance = 0.33f, curb_reflectance = 0.38f;
  std::vector<Primitive> primitives;
  // Windows, doors, ledges and glass on building walls (facade.hpp); off = plain boxes.
  bool facade_detail = false;
  FacadeConfig facade;

  // Builds the DDA grid over `primitives`; call after adding them (and before cast()).
  void build_index(double cell_m = 4.0);

  double ground_height(double x, double y) const;
  bool on_road(double x, double y) const { return road_edge_distance.sample(x, y) <= 0; }
  // First surface hit by the ray (origin, unit direction) within max_range_m.
  // `ray_seed` drives the porous primitives (same seed -> same answer).
  bool cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double max_range_m,
            std::uint64_t ray_seed, RayHit* hit) const;

  std::size_t grid_cells() const { return cell_start_.empty() ? 0 : cell_start_.size() - 1; }

  // Ray against one primitive (also used for the moving objects, which are not indexed):
  // entry distance in (0, t_max) and the normal facing the ray.
  bool hit_primitive(const Primitive& p, std::uint32_t index, const Eigen::Vector3d& o,
                     const Eigen::Vector3d& d, double t_max, std::uint64_t ray_seed,
                     double* t, Eigen::Vector3d* normal) const;

 private:
  bool cast_ground(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_max,
                   RayHit* hit) const;

  double grid_x0_ = 0, grid_y0_ = 0, grid_cell_m_ = 4;
  int grid_nx_ = 0, grid_ny_ = 0;
  double max_object_z_ = 0;
  // Steepest terrain slope within one block of each 32 m block (3x3 dilated): bounds how
  // fast a ray can approach the ground locally, so gentle areas take long march steps.
  Raster2D slope_bound_;
  static constexpr double kSlopeBlock = 32.0;
  std::vector<std::uint32_t> cell_start_, cell_items_;  // CSR: items of cell c
};

}  // namespace scfloam::sim
