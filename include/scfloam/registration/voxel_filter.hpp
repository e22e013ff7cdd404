// Voxel-grid downsampling: one centroid per occupied voxel, as PCL's VoxelGrid does.
#pragma once

#include <Eigen/Geometry>

#include "scfloam/registration/voxel_hash.hpp"
#include "scfloam/registration/voxel_runs.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

class VoxelFilter {
 public:
  // Replaces `out` with the centroids of `in`'s points per leaf_m voxel, in first-seen order.
  // Buffers are kept between calls, so steady-state use allocates nothing. Large clouds are
  // summed in two halves in parallel (TBB).
  void filter(const FeatureCloud& in, double leaf_m, FeatureCloud& out);
  // The centroids of the points whose runs are runs[0], runs[1], ... in that order (summed in
  // voxels of one size): what filter() gives for those points, up to the order of the sums.
  void filter_runs(const std::vector<VoxelRuns>& runs, FeatureCloud& out);

 private:
  // Per-voxel sums of one run of points.
  struct Part {
    FlatKeyIndex index;                 // voxel key -> position in sums
    std::vector<Eigen::Vector4f> sums;  // xyz sum, count; in first-seen order
    std::vector<std::uint64_t> keys;    // the voxel of each sum
    void accumulate(const Eigen::Vector3f* begin, const Eigen::Vector3f* end, float inv,
                    std::size_t expected_voxels);
    void add_runs(const VoxelRuns* begin, const VoxelRuns* end, std::size_t expected_voxels);
    void add(std::uint64_t key, const Eigen::Vector4f& sum);
  };
  void write_centroids(FeatureCloud& out);
  Part first_, second_;
  std::size_t last_voxels_ = 0;  // voxels of the previous call: sizes the tables
};

// Convenience for one-off use (submaps, tests).
FeatureCloud voxel_downsample(const FeatureCloud& in, double leaf_m);

// Points moved into another frame: out[i] = T * in[i].
FeatureCloud transform_cloud(const FeatureCloud& in, const Eigen::Isometry3d& T);

}  // namespace scfloam
