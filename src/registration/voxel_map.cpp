#include "scfloam/registration/voxel_map.hpp"

#include <algorithm>
#include <cmath>

#include "scfloam/error.hpp"

namespace scfloam {

VoxelMap::VoxelMap(double max_query_radius_m, double min_spacing_m, int max_points_per_cell)
    : cell_size_(static_cast<float>(max_query_radius_m)),
      inv_cell_size_(static_cast<float>(1.0 / max_query_radius_m)),
      min_spacing_sq_(static_cast<float>(min_spacing_m * min_spacing_m)),
      max_per_cell_(static_cast<std::uint32_t>(max_points_per_cell)),
      stride_(static_cast<std::uint32_t>(std::max(max_points_per_cell, 1))),
      lines_per_cell_((1 + 3 * std::size_t{stride_} + 15) / 16) {
  if (!(max_query_radius_m > 0)) throw Error("voxel map: query radius must be positive");
  if (max_points_per_cell < 1) throw Error("voxel map: max_points_per_cell must be >= 1");
  brick_index_.reset(64);
}

VoxelMap::VoxelMap(double max_query_radius_m, double min_spacing_m, int max_points_per_cell,
                   double view_tolerance_rad)
    : VoxelMap(max_query_radius_m, min_spacing_m, max_points_per_cell) {
  if (!(view_tolerance_rad >= 0)) throw Error("voxel map: view tolerance must be >= 0");
  if (view_tolerance_rad > 0)
    view_tolerance_ = static_cast<View>(
        std::clamp(std::lround(view_tolerance_rad / (2 * M_PI) * 65536.0), 1l, 32767l));
}

VoxelMap::View VoxelMap::view_of(const Eigen::Vector3f& sensor, const Eigen::Vector3f& point) {
  const float az = std::atan2(point.y() - sensor.y(), point.x() - sensor.x());
  return static_cast<View>(static_cast<std::int32_t>(std::lround(az * (65536.0 / (2 * M_PI)))) & 0xffff);
}

std::uint32_t VoxelMap::index_cell(const Eigen::Vector3i& c, std::uint32_t cell) {
  const auto fresh = static_cast<std::uint32_t>(bricks_.size() / kBrickCells);
  const std::uint32_t brick = brick_index_.insert(brick_key(c), fresh);
  if (brick == fresh) bricks_.resize(bricks_.size() + kBrickCells, FlatKeyIndex::kNone);
  bricks_[std::size_t{brick} * kBrickCells + index_in_brick(c)] = cell;
  return brick;
}

std::uint32_t VoxelMap::cell_at(const Eigen::Vector3i& c, BrickCursor& cursor) {
  const std::uint64_t key = brick_key(c);
  if (key != cursor.key) {
    cursor.key = key;
    cursor.brick = brick_index_.find(key);
  }
  if (cursor.brick != FlatKeyIndex::kNone) {
    const std::uint32_t cell = bricks_[std::size_t{cursor.brick} * kBrickCells + index_in_brick(c)];
    if (cell != FlatKeyIndex::kNone) return cell;
  }
  const auto cell = static_cast<std::uint32_t>(cells_.size());
  cursor.brick = index_cell(c, cell);
  cells_.push_back(c);
  lines_.resize(lines_.size() + lines_per_cell_);
  set_cell_count(cell, 0);
  if (stores_views()) views_.resize(views_.size() + stride_);
  return cell;
}

std::size_t VoxelMap::insert(const FeatureCloud& points_lidar,
                             const Eigen::Isometry3d& T_world_lidar) {
  const Eigen::Isometry3f T = T_world_lidar.cast<float>();
  const Eigen::Vector3f sensor = T.translation();
  const bool views = stores_views();
  std::size_t stored = 0;
  BrickCursor cursor;
  for (const auto& pl : points_lidar) {
    const Eigen::Vector3f p = T * pl;
    const View view = views ? view_of(sensor, p) : View{0};
    const std::uint32_t cell = cell_at(voxel_coords(p, inv_cell_size_), cursor);
    const std::uint32_t count = cell_count(cell);
    if (count >= max_per_cell_) continue;
    float* xyz = cell_xyz(cell);
    bool too_close = false;
    for (std::uint32_t i = 0; i < count && !too_close; ++i) {
      const float dx = xyz[3 * i] - p.x(), dy = xyz[3 * i + 1] - p.y(), dz = xyz[3 * i + 2] - p.z();
      too_close = dx * dx + dy * dy + dz * dz < min_spacing_sq_ &&
                  (!views || view_close(cell_views(cell)[i], view));
    }
    if (too_close) continue;
    if (views) cell_views(cell)[count] = view;
    xyz[3 * count] = p.x();
    xyz[3 * count + 1] = p.y();
    xyz[3 * count + 2] = p.z();
    set_cell_count(cell, count + 1);
    ++num_points_;
    ++stored;
  }
  return stored;
}

void VoxelMap::knn(const Eigen::Vector3f& q, int k, float radius_m, Neighbors& out,
                   const View* view) const {
  if (view && !stores_views()) view = nullptr;
  k = std::min(k, kMaxK);
  out.count = 0;
  if (k <= 0) return;
  const float r2 = radius_m * radius_m;
  const Eigen::Vector3f s = q * inv_cell_size_;
  const Eigen::Vector3i c(static_cast<int>(std::floor(s.x())), static_cast<int>(std::floor(s.y())),
                          static_cast<int>(std::floor(s.z())));
  // Squared distance from q to the lower / upper face of its cell, per axis: face2[a][0] for
  // offset -1, [1] = 0 for its own slab, [2] for +1. A neighbour's box distance is then three
  // table reads (this loop runs 27 times per query, the hottest part of the search).
  float face2[3][3];
  for (int a = 0; a < 3; ++a) {
    const float f = (s[a] - c[a]) * cell_size_;
    face2[a][0] = f * f;
    face2[a][1] = 0.f;
    face2[a][2] = (cell_size_ - f) * (cell_size_ - f);
  }
  // Cells are `radius` wide, so the ball lies in the 27 around q's cell. Visit q's own cell,
  // then faces, edges and corners; skip a cell whose box is farther than the current k-th
  // neighbour (or the radius): most queries read only five or six cells.
  static constexpr int kOrder[27][3] = {
      {0, 0, 0},   {-1, 0, 0},  {1, 0, 0},   {0, -1, 0},  {0, 1, 0},   {0, 0, -1}, {0, 0, 1},
      {-1, -1, 0}, {-1, 1, 0},  {1, -1, 0},  {1, 1, 0},   {-1, 0, -1}, {-1, 0, 1}, {1, 0, -1},
      {1, 0, 1},   {0, -1, -1}, {0, -1, 1},  {0, 1, -1},  {0, 1, 1},   {-1, -1, -1},
      {-1, -1, 1}, {-1, 1, -1}, {-1, 1, 1},  {1, -1, -1}, {1, -1, 1},  {1, 1, -1}, {1, 1, 1}};
  // `bound` is the k-th distance once k are found, else r^2; each closer point is merged into
  // the sorted best k.
  const float qx = q.x(), qy = q.y(), qz = q.z();
  float bound = r2;
  const Eigen::Vector3i low((c.x() - 1) >> kBrickShift, (c.y() - 1) >> kBrickShift,
                            (c.z() - 1) >> kBrickShift);
  const std::uint32_t* bricks[8];
  bool brick_known[8] = {false, false, false, false, false, false, false, false};
  for (const auto& o : kOrder) {
    const float box2 = face2[0][o[0] + 1] + face2[1][o[1] + 1] + face2[2][o[2] + 1];
    if (box2 >= bound) continue;
    const Eigen::Vector3i cn(c.x() + o[0], c.y() + o[1], c.z() + o[2]);
    // The 3x3x3 block spans at most two bricks per axis: slot (bx, by, bz) - low brick.
    const int slot = (((cn.x() >> kBrickShift) - low.x()) << 2) |
                     (((cn.y() >> kBrickShift) - low.y()) << 1) | ((cn.z() >> kBrickShift) - low.z());
    if (!brick_known[slot]) {
      brick_known[slot] = true;
      bricks[slot] = find_brick(brick_key(cn));
    }
    if (!bricks[slot]) continue;
    const std::uint32_t cell = bricks[slot][index_in_brick(cn)];
    if (cell == FlatKeyIndex::kNone) continue;
    const float* xyz = cell_xyz(cell);
    const std::uint32_t n = cell_count(cell);
    const View* views = view ? cell_views(cell) : nullptr;
    for (std::uint32_t i = 0; i < n; ++i, xyz += 3) {
      if (views && !view_close(views[i], *view)) continue;
      const float dx = xyz[0] - qx, dy = xyz[1] - qy, dz = xyz[2] - qz;
      const float d = dx * dx + dy * dy + dz * dz;
      if (d >= bound) continue;
      int j = out.count < k ? out.count++ : k - 1;  // insertion sort into the best k
      while (j > 0 && out.sq_dist[j - 1] > d) {
        out.sq_dist[j] = out.sq_dist[j - 1];
        out.points[j] = out.points[j - 1];
        --j;
      }
      out.sq_dist[j] = d;
      out.points[j] = Eigen::Vector3f(xyz[0], xyz[1], xyz[2]);
      if (out.count == k) bound = out.sq_dist[k - 1];
    }
  }
}

void VoxelMap::remove_far(const Eigen::Vector3d& center, double radius_m) {
  const Eigen::Vector3f cf = center.cast<float>();
  const float r2 = static_cast<float>(radius_m * radius_m);
  std::size_t kept = 0;
  num_points_ = 0;
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    const Eigen::Vector3f mid = (cells_[i].cast<float>().array() + 0.5f) * cell_size_;
    if ((mid - cf).squaredNorm() > r2) continue;
    if (kept != i) {
      cells_[kept] = cells_[i];
      std::copy_n(&lines_[i * lines_per_cell_], lines_per_cell_, &lines_[kept * lines_per_cell_]);
      if (stores_views()) std::copy_n(cell_views(i), stride_, cell_views(kept));
    }
    num_points_ += cell_count(kept);
    ++kept;
  }
  if (kept == cells_.size()) return;
  cells_.resize(kept);
  lines_.resize(kept * lines_per_cell_);
  if (stores_views()) views_.resize(kept * stride_);
  rebuild_bricks();
}

void VoxelMap::rebuild_bricks() {
  bricks_.clear();
  brick_index_.reset(cells_.size() / 16 + 64);
  for (std::size_t i = 0; i < cells_.size(); ++i)
    index_cell(cells_[i], static_cast<std::uint32_t>(i));
}

void VoxelMap::clear() {
  cells_.clear();
  lines_.clear();
  views_.clear();
  rebuild_bricks();
  num_points_ = 0;
}

FeatureCloud VoxelMap::points() const {
  FeatureCloud out;
  out.reserve(num_points_);
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    const float* xyz = cell_xyz(i);
    for (std::uint32_t j = 0, n = cell_count(i); j < n; ++j)
      out.emplace_back(xyz[3 * j], xyz[3 * j + 1], xyz[3 * j + 2]);
  }
  return out;
}

}  // namespace scfloam
