#include "scfloam/registration/voxel_filter.hpp"

#include "scfloam/error.hpp"

namespace scfloam {

void VoxelFilter::filter(const FeatureCloud& in, double leaf_m, FeatureCloud& out) {
  if (!(leaf_m > 0)) throw Error("voxel filter: leaf size must be positive");
  const float inv = static_cast<float>(1.0 / leaf_m);
  index_.reset(in.size() / 2 + 16);
  sums_.clear();
  for (const auto& p : in) {
    const Eigen::Vector3i c = voxel_coords(p, inv);
    const std::uint32_t slot =
        index_.insert(voxel_key(c.x(), c.y(), c.z()), static_cast<std::uint32_t>(sums_.size()));
    if (slot == sums_.size()) sums_.emplace_back(0.f, 0.f, 0.f, 0.f);
    sums_[slot] += Eigen::Vector4f(p.x(), p.y(), p.z(), 1.f);
  }
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
