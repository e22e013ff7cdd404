#include "scfloam/registration/voxel_map.hpp"

#include <algorithm>

#include "scfloam/error.hpp"

namespace scfloam {

VoxelMap::VoxelMap(double max_query_radius_m, double min_spacing_m, int max_points_per_cell)
    : cell_size_(static_cast<float>(max_query_radius_m)),
      inv_cell_size_(static_cast<float>(1.0 / max_query_radius_m)),
      min_spacing_sq_(static_cast<float>(min_spacing_m * min_spacing_m)),
      max_per_cell_(static_cast<std::uint32_t>(max_points_per_cell)),
      stride_((static_cast<std::uint32_t>(std::max(max_points_per_cell, 1)) + 7u) & ~7u) {
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
      pool_.resize(pool_.size() + 3 * stride_);
    }
    Cell& cl = cells_[cell];
    if (cl.count >= max_per_cell_) continue;
    float* xs = cell_xyz(cell);
    float* ys = xs + stride_;
    float* zs = ys + stride_;
    bool too_close = false;
    for (std::uint32_t i = 0; i < cl.count && !too_close; ++i) {
      const float dx = xs[i] - p.x(), dy = ys[i] - p.y(), dz = zs[i] - p.z();
      too_close = dx * dx + dy * dy + dz * dz < min_spacing_sq_;
    }
    if (too_close) continue;
    xs[cl.count] = p.x();
    ys[cl.count] = p.y();
    zs[cl.count] = p.z();
    ++cl.count;
    ++num_points_;
    ++stored;
  }
  return stored;
}

void VoxelMap::knn(const Eigen::Vector3f& q, int k, float radius_m, Neighbors& out) const {
  k = std::min(k, kMaxK);
  out.count = 0;
  if (k <= 0) return;
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
  // Squared distances of a block of a cell's points, computed together (vectorizes), then
  // merged into the sorted best k; `bound` is the k-th distance once k are found, else r^2.
  constexpr std::uint32_t kBlock = 32;
  float d2[kBlock];
  float bound = r2;
  for (const auto& o : kOrder) {
    float box2 = 0;
    for (int a = 0; a < 3; ++a) box2 += o[a] < 0 ? lo2[a] : (o[a] > 0 ? hi2[a] : 0.f);
    if (box2 >= bound) continue;
    const std::uint32_t cell = index_.find(voxel_key(c.x() + o[0], c.y() + o[1], c.z() + o[2]));
    if (cell == FlatKeyIndex::kNone) continue;
    const float* xs = cell_xyz(cell);
    const float* ys = xs + stride_;
    const float* zs = ys + stride_;
    const std::uint32_t n = cells_[cell].count;
    for (std::uint32_t b = 0; b < n; b += kBlock) {
      const std::uint32_t m = std::min(kBlock, n - b);
      for (std::uint32_t i = 0; i < m; ++i) {
        const float dx = xs[b + i] - q.x(), dy = ys[b + i] - q.y(), dz = zs[b + i] - q.z();
        d2[i] = dx * dx + dy * dy + dz * dz;
      }
      for (std::uint32_t i = 0; i < m; ++i) {
        const float d = d2[i];
        if (d >= bound) continue;
        int j = out.count < k ? out.count++ : k - 1;  // insertion sort into the best k
        while (j > 0 && out.sq_dist[j - 1] > d) {
          out.sq_dist[j] = out.sq_dist[j - 1];
          out.points[j] = out.points[j - 1];
          --j;
        }
        out.sq_dist[j] = d;
        out.points[j] = Eigen::Vector3f(xs[b + i], ys[b + i], zs[b + i]);
        if (out.count == k) bound = out.sq_dist[k - 1];
      }
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
      std::copy_n(cell_xyz(i), 3 * stride_, cell_xyz(kept));
    }
    num_points_ += cells_[kept].count;
    ++kept;
  }
  if (kept == cells_.size()) return;
  cells_.resize(kept);
  pool_.resize(kept * 3 * stride_);
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
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    const float* xs = cell_xyz(i);
    for (std::uint32_t j = 0; j < cells_[i].count; ++j)
      out.emplace_back(xs[j], xs[stride_ + j], xs[2 * stride_ + j]);
  }
  return out;
}

}  // namespace scfloam
