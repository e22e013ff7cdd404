// Incremental local map of feature points: cells with a bounded number of points each, found
// through a hash of 8x8x8-cell bricks.
// Replaces F-LOAM's "crop the map and rebuild a k-d tree every frame": inserting a frame and
// dropping far cells cost O(points touched), and a k-nearest query reads the few cells of the
// 27 around it that can still hold a closer point.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <cstring>
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
  // Cells are found through bricks of 8x8x8 cells: a hash table maps a brick's coordinates to
  // a dense block of its 512 cell numbers (kNone where empty). The up to 27 cells a query
  // visits mostly lie in one or two bricks, whose entries for neighbouring cells share cache
  // lines, where a hash of every cell scattered them over the table: the search waits on
  // memory, not arithmetic (docs/odometry.md, "Session 27").
  static constexpr int kBrickShift = 3;
  static constexpr int kBrickCells = 1 << (3 * kBrickShift);
  static std::uint64_t brick_key(const Eigen::Vector3i& c) {
    return voxel_key(c.x() >> kBrickShift, c.y() >> kBrickShift, c.z() >> kBrickShift);
  }
  static int index_in_brick(const Eigen::Vector3i& c) {
    constexpr int m = (1 << kBrickShift) - 1;
    return ((c.x() & m) << (2 * kBrickShift)) | ((c.y() & m) << kBrickShift) | (c.z() & m);
  }
  const std::uint32_t* find_brick(std::uint64_t key) const {
    const std::uint32_t b = brick_index_.find(key);
    return b == FlatKeyIndex::kNone ? nullptr : &bricks_[std::size_t{b} * kBrickCells];
  }
  // The cell at c, created (empty) if it does not exist yet. `cursor` remembers the last
  // brick: consecutive points of a scan mostly fall into the same one.
  struct BrickCursor {
    std::uint64_t key = ~std::uint64_t{0};  // no brick has this key
    std::uint32_t brick = FlatKeyIndex::kNone;
  };
  std::uint32_t cell_at(const Eigen::Vector3i& c, BrickCursor& cursor);
  std::uint32_t index_cell(const Eigen::Vector3i& c, std::uint32_t cell);  // returns the brick
  void rebuild_bricks();  // after cells were dropped or moved

  // Cell c's block starts at a cache line: its point count, then x y z of each point. The count
  // sits with the first points, so a query's first read of a cell is one line, not two; x y z
  // interleaved rather than in three arrays for the same reason (measured, docs/odometry.md).
  struct alignas(64) Line {
    float f[16];
  };
  float* cell_xyz(std::size_t cell) { return lines_[cell * lines_per_cell_].f + 1; }
  const float* cell_xyz(std::size_t cell) const { return lines_[cell * lines_per_cell_].f + 1; }
  std::uint32_t cell_count(std::size_t cell) const {
    std::uint32_t n;
    std::memcpy(&n, lines_[cell * lines_per_cell_].f, sizeof n);
    return n;
  }
  void set_cell_count(std::size_t cell, std::uint32_t n) {
    std::memcpy(lines_[cell * lines_per_cell_].f, &n, sizeof n);
  }

  View* cell_views(std::size_t cell) { return &views_[cell * stride_]; }
  const View* cell_views(std::size_t cell) const { return &views_[cell * stride_]; }
  bool view_close(View a, View b) const {
    const int d = static_cast<std::int16_t>(static_cast<View>(a - b));  // wrapped, signed
    return std::abs(d) <= view_tolerance_;
  }

  float cell_size_, inv_cell_size_, min_spacing_sq_;
  View view_tolerance_ = 0;  // 0 = views not stored
  std::uint32_t max_per_cell_;
  std::uint32_t stride_;          // points a cell has room for (max_per_cell_)
  std::size_t lines_per_cell_;    // cache lines of a cell's block
  FlatKeyIndex brick_index_;
  std::vector<std::uint32_t> bricks_;  // kBrickCells cell numbers per brick
  std::vector<Eigen::Vector3i> cells_;  // each cell's coordinates
  std::vector<Line> lines_;             // lines_per_cell_ per cell
  std::vector<View> views_;             // stride_ per cell when views are stored, else empty
  std::size_t num_points_ = 0;
};

}  // namespace scfloam
