#include "scfloam/registration/voxel_filter.hpp"

#include <algorithm>

#include "scfloam/error.hpp"

namespace scfloam {

void VoxelFilter::filter(const FeatureCloud& in, double leaf_m, FeatureCloud& out) {
  if (!(leaf_m > 0)) throw Error("voxel filter: leaf size must be positive");
  const float inv = static_cast<float>(1.0 / leaf_m);
  // Size the table for the voxels of the previous call, not for every input point: a frame's
  // ~100k plane points fill only ~8k voxels, and a table that fits in cache is several times
  // faster to clear and probe (it grows if the guess is short).
  index_.reset(std::min(in.size(), std::max<std::size_t>(last_voxels_, 1024)) + 16);
  sums_.clear();
  // Feature clouds come ring by ring in azimuth order, so a run of consecutive points usually
  // shares a voxel: sum the run in registers and probe the table only when the voxel changes.
  // (Scalar sums: building an Eigen::Vector4f per point from x, y, z, 1 went through the stack
  // and stalled on a failed store-to-load forward, ~25 ns a point.)
  std::uint64_t run_key = 0;
  float sx = 0, sy = 0, sz = 0, count = 0;
  const auto flush = [&]() {
    if (count == 0) return;
    const Eigen::Vector4f run(sx, sy, sz, count);
    const std::uint32_t slot = index_.insert(run_key, static_cast<std::uint32_t>(sums_.size()));
    if (slot == sums_.size()) sums_.push_back(run);
    else sums_[slot] += run;
  };
  for (const auto& p : in) {
    const Eigen::Vector3i c = voxel_coords(p, inv);
    const std::uint64_t key = voxel_key(c.x(), c.y(), c.z());
    if (key != run_key) {
      flush();
      run_key = key;
      sx = sy = sz = count = 0;
    }
    sx += p.x();
    sy += p.y();
    sz += p.z();
    count += 1;
  }
  flush();
  last_voxels_ = sums_.size();
  out.resize(sums_.size());
  for (std::size_t i = 0; i < sums_.size(); ++i) out[i] = sums_[i].head<3>() / sums_[i].w();
}

FeatureCloud voxel_downsample(const FeatureCloud& in, double leaf_m) {
  VoxelFilter f;
  FeatureCloud out;
  f.filter(in, leaf_m, out);
  return out;
}

FeatureCloud transform_cloud(const FeatureCloud& in, const Eigen::Isometry3d& T) {
  const Eigen::Isometry3f Tf = T.cast<float>();
  FeatureCloud out(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) out[i] = Tf * in[i];
  return out;
}

}  // namespace scfloam
