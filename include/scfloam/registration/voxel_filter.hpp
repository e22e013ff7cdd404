// Voxel-grid downsampling: one centroid per occupied voxel, as PCL's VoxelGrid does.
#pragma once

#include <Eigen/Geometry>

#include "scfloam/registration/voxel_hash.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

class VoxelFilter {
 public:
  // Replaces `out` with the centroids of `in`'s points per leaf_m voxel, in first-seen order.
  // Buffers are kept between calls, so steady-state use allocates nothing.
  void filter(const FeatureCloud& in, double leaf_m, FeatureCloud& out);

 private:
  FlatKeyIndex index_;
  std::vector<Eigen::Vector4f> sums_;  // xyz sum, count
  std::size_t last_voxels_ = 0;        // voxels of the previous call: sizes the table
};

// Convenience for one-off use (submaps, tests).
FeatureCloud voxel_downsample(const FeatureCloud& in, double leaf_m);

// Points moved into another frame: out[i] = T * in[i].
FeatureCloud transform_cloud(const FeatureCloud& in, const Eigen::Isometry3d& T);

}  // namespace scfloam
