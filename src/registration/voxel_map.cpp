#include "scfloam/registration/voxel_map.hpp"

#include <algorithm>

#include "scfloam/error.hpp"

namespace scfloam {

VoxelMap::VoxelMap(double max_query_radius_m, double min_spacing_m, int max_points_per_cell)
    : cell_size_(static_cast<float>(max_query_radius_m)),
      inv_cell_size_(static_cast<float>(1.0 / max_query_radius_m)),
      min_spacing_sq_(static_cast<float>(min_spacing_m * min_spacing_m)),
      max_per_cell_(static_cast<std::uint32_t>(max_points_per_cell)) {
  if (!(max_query_radius_m > 0)) throw Error("voxel map: query radius must be positive");
  if (max_points_per_cell < 1) throw Error("voxel map: max_points_per_cell must be >= 1");
  index_.reset(1024);
}

std::size_t VoxelMap::insert(const FeatureCloud& points_lidar,
                             const Eigen::Isometry3d& T_world_lidar) {
  const Eigen::Isometry3f T = T_world_lidar.cast<float>();
  std::size_t stored = 0;
  for (const auto& pl : points_lidar) {
    const Eigen::Vector3f p = T * pl;
    const Eigen::Vector3i c = voxel_coords(p, inv_cell_size_);
    const auto id = static_cast<std::uint32_t>(cells_.size());
    const std::uint32_t cell = index_.insert(voxel_key(c.x(), c.y(), c.z()), id);
    if (cell == id) {
      cells_.push_back(Cell{c, 0});
      pool_.resize(pool_.size() + max_per_cell_);
    }
    Cell& cl = cells_[cell];
    if (cl.count >= max_per_cell_) continue;
    Eigen::Vector3f* pts = &pool_[static_cast<std::size_t>(cell) * max_per_cell_];
    bool too_close = false;
    for (std::uint32_t i = 0; i < cl.count && !too_close; ++i)
      too_close = (pts[i] - p).squaredNorm() < min_spacing_sq_;
    if (too_close) continue;
    pts[cl.count++] = p;
    ++num_points_;
    ++stored;
  }
  return stored;
}

void VoxelMap::knn(const Eigen::Vector3f& q, int k, float radius_m, Neighbors& out) const {
  k = std::min(k, kMaxK);
  out.count = 0;
  const float r2 = radius_m * radius_m;
  const Eigen::Vector3f s = q * inv_cell_size_;
  const Eigen::Vector3i c(static_cast<int>(std::floor(s.x())), static_cast<int>(std::floor(s.y())),
                          static_cast<int>(std::floor(s.z())));
  // Squared distance from q to the lower / upper face of its cell, per axis.
  float lo2[3], hi2[3];
  for (int a = 0; a < 3; ++a) {
    const float f = (s[a] - c[a]) * cell_size_;
    lo2[a] = f * f;
    hi2[a] = (cell_size_ - f) * (cell_size_ - f);
  }
  // Cells are `radius` wide, so the ball lies in the 27 around q's cell. Visit q's own cell,
  // then faces, edges and corners; skip a cell whose box is farther than the current k-th
  // neighbour (or the radius): most queries read only two or three cells.
  static constexpr int kOrder[27][3] = {
      {0, 0, 0},   {-1, 0, 0},  {1, 0, 0},   {0, -1, 0},  {0, 1, 0},   {0, 0, -1}, {0, 0, 1},
      {-1, -1, 0}, {-1, 1, 0},  {1, -1, 0},  {1, 1, 0},   {-1, 0, -1}, {-1, 0, 1}, {1, 0, -1},
      {1, 0, 1},   {0, -1, -1}, {0, -1, 1},  {0, 1, -1},  {0, 1, 1},   {-1, -1, -1},
      {-1, -1, 1}, {-1, 1, -1}, {-1, 1, 1},  {1, -1, -1}, {1, -1, 1},  {1, 1, -1}, {1, 1, 1}};
  for (const auto& o : kOrder) {
    float box2 = 0;
    for (int a = 0; a < 3; ++a) box2 += o[a] < 0 ? lo2[a] : (o[a] > 0 ? hi2[a] : 0.f);
    const float bound = out.count == k ? out.sq_dist[k - 1] : r2;
    if (box2 >= bound) continue;
    const std::uint32_t cell = index_.find(voxel_key(c.x() + o[0], c.y() + o[1], c.z() + o[2]));
    if (cell == FlatKeyIndex::kNone) continue;
    const Eigen::Vector3f* pts = cell_points(cell);
    const std::uint32_t n = cells_[cell].count;
    for (std::uint32_t i = 0; i < n; ++i) {
      const float d2 = (pts[i] - q).squaredNorm();
      if (d2 >= r2 || (out.count == k && d2 >= out.sq_dist[k - 1])) continue;
      int j = out.count < k ? out.count++ : k - 1;  // insertion sort into the best k
      while (j > 0 && out.sq_dist[j - 1] > d2) {
        out.sq_dist[j] = out.sq_dist[j - 1];
        out.points[j] = out.points[j - 1];
        --j;
      }
      out.sq_dist[j] = d2;
      out.points[j] = pts[i];
    }
  }
}

void VoxelMap::remove_far(const Eigen::Vector3d& center, double radius_m) {
  const Eigen::Vector3f cf = center.cast<float>();
  const float r2 = static_cast<float>(radius_m * radius_m);
  std::size_t kept = 0;
  num_points_ = 0;
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    const Eigen::Vector3f mid = (cells_[i].coords.cast<float>().array() + 0.5f) * cell_size_;
    if ((mid - cf).squaredNorm() > r2) continue;
    if (kept != i) {
      cells_[kept] = cells_[i];
      std::copy_n(&pool_[i * max_per_cell_], max_per_cell_, &pool_[kept * max_per_cell_]);
    }
    num_points_ += cells_[kept].count;
    ++kept;
  }
  if (kept == cells_.size()) return;
  cells_.resize(kept);
  pool_.resize(kept * max_per_cell_);
  index_.reset(kept + 1024);
  for (std::size_t i = 0; i < kept; ++i) {
    const auto& c = cells_[i].coords;
    index_.insert(voxel_key(c.x(), c.y(), c.z()), static_cast<std::uint32_t>(i));
  }
}

void VoxelMap::clear() {
  cells_.clear();
  pool_.clear();
  index_.reset(1024);
  num_points_ = 0;
}

FeatureCloud VoxelMap::points() const {
  FeatureCloud out;
  out.reserve(num_points_);
  for (std::size_t i = 0; i < cells_.size(); ++i)
    for (std::uint32_t j = 0; j < cells_[i].count; ++j) out.push_back(pool_[i * max_per_cell_ + j]);
  return out;
}

}  // namespace scfloam
