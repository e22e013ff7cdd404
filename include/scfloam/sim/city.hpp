// Procedural city: streets (polylines with a width), terrain, and the objects along them —
// buildings of varied footprint and height, trees, poles, signs, parked cars, fences, parks
// and parking lots. The same street-side placer serves the grid city and the worlds built
// around a replayed KITTI trajectory.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "scfloam/sim/world.hpp"

namespace scfloam::sim {

struct Street {
  std::vector<Eigen::Vector2d> centerline;  // at least two points
  double half_width_m = 6.5;                // curb to centerline
  double sidewalk_m = 3.0;                  // curb to the building line
  bool tree_lined = false;
  bool parking = true;                      // parked cars along both curbs
  // Keep buildings this far beyond the sidewalk (lets a replayed path stay clear).
  double extra_setback_m = 0;
};

struct WorldBounds {
  double xmin = 0, ymin = 0, xmax = 0, ymax = 0;
};
WorldBounds bounds_of(const std::vector<Street>& streets, double margin_m);

// Gentle rolling terrain: a few long-wavelength waves, steepest slope about max_slope.
Raster2D make_rolling_terrain(const WorldBounds& bounds, std::uint64_t seed, double max_slope);
// Terrain through given ground points (x, y, z) (a replayed path): smooth, flat far away,
// and nowhere steeper than max_slope (conflicting heights of two passes are relaxed).
Raster2D fit_terrain(const WorldBounds& bounds, const std::vector<Eigen::Vector3d>& ground_points,
                     double max_slope = 0.12);

struct CityStats {
  std::size_t buildings = 0, trees = 0, poles = 0, cars = 0, signs = 0, fences = 0;
};

// Rasterizes the streets (curbs), then places the objects from `seed`. The terrain raster
// must cover the bounds. Objects never stand on a roadway except parked cars, which stay
// next to the curb, at least ~3.9 m from every centerline.
World build_city(const std::vector<Street>& streets, Raster2D terrain, std::uint64_t seed,
                 CityStats* stats = nullptr);

}  // namespace scfloam::sim
