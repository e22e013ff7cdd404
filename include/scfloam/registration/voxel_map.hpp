// Incremental local map of feature points: hash cells with a bounded number of points each.
// Replaces F-LOAM's "crop the map and rebuild a k-d tree every frame": inserting a frame and
// dropping far cells cost O(points touched), and a k-nearest query reads the few cells of the
// 27 around it that can still hold a closer point.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdlib>
#include <cstdint>
#include <vector>

#include "scfloam/config.hpp"
#include "scfloam/registration/voxel_hash.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

class VoxelMap {
 public:
  static constexpr int kMaxK = kMaxRegistrationKnn;

  struct Neighbors {
    std::array<Eigen::Vector3f, kMaxK> points;
    std::array<float, kMaxK> sq_dist;
    int count = 0;  // sorted by distance, nearest first
  };

  // Queries are exact within `max_query_radius_m` (the cell width). A point is not
  // stored when one already in its cell lies within `min_spacing_m`, or the cell is full.
  VoxelMap(double max_query_radius_m, double min_spacing_m, int max_points_per_cell);
  // With view_tolerance_rad > 0 every point also keeps the horizontal direction it was seen
  // in (sensor to point, world frame), spacing counts only against points seen within that
  // angle, and knn can be asked for such points only (see ViewFilter).
  VoxelMap(double max_query_radius_m, double min_spacing_m, int max_points_per_cell,
           double view_tolerance_rad);

  // A horizontal viewing direction, quantised to 1/65536 of a turn (wraps like angles do).
  using View = std::uint16_t;
  static View view_of(const Eigen::Vector3f& sensor, const Eigen::Vector3f& point);
  bool stores_views() const { return view_tolerance_ != 0; }

  // Adds T_world_lidar * p for every p in `points_lidar`; returns how many were stored.
  std::size_t insert(const FeatureCloud& points_lidar, const Eigen::Isometry3d& T_world_lidar);

  // The k (<= kMaxK) nearest stored points within `radius_m` (<= max_query_radius_m) of q.
  void knn(const Eigen::Vector3f& q, int k, float radius_m, Neighbors& out) const {
    knn(q, k, radius_m, out, nullptr);
  }
  // The same among points seen within the map's view tolerance of *view (nullptr = all).
  void knn(const Eigen::Vector3f& q, int k, float radius_m, Neighbors& out,
           const View* view) const;

  // Drops every cell whose centre lies farther than radius_m from `center`.
  void remove_far(const Eigen::Vector3d& center, double radius_m);

  void clear();
  std::size_t num_points() const { return num_points_; }
  std::size_t num_cells() const { return cells_.size(); }
  double max_query_radius_m() const { return cell_size_; }
  // Every stored point (for saving maps and debugging; order unspecified).
  FeatureCloud points() const;

 private:
  struct Cell {
    Eigen::Vector3i coords;
    std::uint32_t count = 0;
  };

  // Cell c's points live at pool_[c * 3 * stride_], x y z after each other. Interleaved, not a
  // structure of arrays: a query reads ~5 cells of ~5 points each, and the search waits on
  // memory, so one or two cache lines per cell beat three (measured, docs/odometry.md).
  float* cell_xyz(std::size_t cell) { return &pool_[cell * 3 * stride_]; }
  const float* cell_xyz(std::size_t cell) const { return &pool_[cell * 3 * stride_]; }

  View* cell_views(std::size_t cell) { return &views_[cell * stride_]; }
  const View* cell_views(std::size_t cell) const { return &views_[cell * stride_]; }
  bool view_close(View a, View b) const {
    const int d = static_cast<std::int16_t>(static_cast<View>(a - b));  // wrapped, signed
    return std::abs(d) <= view_tolerance_;
  }

  float cell_size_, inv_cell_size_, min_spacing_sq_;
  View view_tolerance_ = 0;  // 0 = views not stored
  std::uint32_t max_per_cell_;
  std::uint32_t stride_;  // points a cell has room for (max_per_cell_)
  FlatKeyIndex index_;
  std::vector<Cell> cells_;
  std::vector<float> pool_;  // 3 * stride_ floats per cell
  std::vector<View> views_;  // stride_ per cell when views are stored, else empty
  std::size_t num_points_ = 0;
};

}  // namespace scfloam
