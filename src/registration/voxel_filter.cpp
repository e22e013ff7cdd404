#include "scfloam/registration/voxel_filter.hpp"

#include <tbb/parallel_invoke.h>

#include <algorithm>

#include "scfloam/error.hpp"

namespace scfloam {

void VoxelFilter::Part::accumulate(const Eigen::Vector3f* begin, const Eigen::Vector3f* end,
                                   float inv, std::size_t expected_voxels) {
  // Size the table for the voxels of the previous call, not for every input point: a frame's
  // ~100k plane points fill only ~8k voxels, and a table that fits in cache is several times
  // faster to clear and probe (it grows if the guess is short).
  index.reset(std::min(static_cast<std::size_t>(end - begin), expected_voxels) + 16);
  sums.clear();
  keys.clear();
  for_each_voxel_run(begin, end, inv, [&](std::uint64_t key, const Eigen::Vector4f& sum) { add(key, sum); });
}

void VoxelFilter::Part::add_runs(const VoxelRuns* begin, const VoxelRuns* end, std::size_t expected_voxels) {
  std::size_t n = 0;
  for (const VoxelRuns* r = begin; r != end; ++r) n += r->keys.size();
  index.reset(std::min(n, expected_voxels) + 16);
  sums.clear();
  keys.clear();
  for (const VoxelRuns* r = begin; r != end; ++r)
    for (std::size_t i = 0; i < r->keys.size(); ++i) add(r->keys[i], r->sums[i]);
}

void VoxelFilter::Part::add(std::uint64_t key, const Eigen::Vector4f& sum) {
  const std::uint32_t slot = index.insert(key, static_cast<std::uint32_t>(sums.size()));
  if (slot == sums.size()) {
    sums.push_back(sum);
    keys.push_back(key);
  } else {
    sums[slot] += sum;
  }
}

void VoxelFilter::filter(const FeatureCloud& in, double leaf_m, FeatureCloud& out) {
  if (!(leaf_m > 0)) throw Error("voxel filter: leaf size must be positive");
  const float inv = static_cast<float>(1.0 / leaf_m);
  const std::size_t expected = std::max<std::size_t>(last_voxels_, 1024);
  const Eigen::Vector3f* p = in.data();
  const std::size_t n = in.size();
  // Large clouds (a frame's ~100k plane points) in two halves on two threads; the second
  // half's voxels are then merged into the first's. A voxel first seen in the first half keeps
  // that place and the second half's new voxels follow in their order, so the output is in
  // first-seen order as from one pass; only the sums' association differs. The split is
  // fixed, so the result does not depend on the scheduling.
  constexpr std::size_t kParallelMin = 32768;
  if (n < kParallelMin) {
    first_.accumulate(p, p + n, inv, expected);
  } else {
    const std::size_t half = n / 2;
    tbb::parallel_invoke([&] { first_.accumulate(p, p + half, inv, expected); },
                         [&] { second_.accumulate(p + half, p + n, inv, expected); });
    for (std::size_t i = 0; i < second_.sums.size(); ++i) first_.add(second_.keys[i], second_.sums[i]);
  }
  write_centroids(out);
}

void VoxelFilter::filter_runs(const std::vector<VoxelRuns>& runs, FeatureCloud& out) {
  const std::size_t expected = std::max<std::size_t>(last_voxels_, 1024);
  std::size_t total = 0;
  for (const VoxelRuns& r : runs) total += r.keys.size();
  // As filter(): many runs in two parts on two threads, split where half the runs are done
  // (a split fixed by the input, so the result does not depend on the scheduling).
  constexpr std::size_t kParallelMin = 4096;
  const VoxelRuns* b = runs.data();
  const VoxelRuns* e = b + runs.size();
  if (total < kParallelMin) {
    first_.add_runs(b, e, expected);
  } else {
    const VoxelRuns* split = b;
    for (std::size_t done = 0; split != e && 2 * done < total; ++split) done += split->keys.size();
    tbb::parallel_invoke([&] { first_.add_runs(b, split, expected); },
                         [&] { second_.add_runs(split, e, expected); });
    for (std::size_t i = 0; i < second_.sums.size(); ++i) first_.add(second_.keys[i], second_.sums[i]);
  }
  write_centroids(out);
}

void VoxelFilter::write_centroids(FeatureCloud& out) {
  const std::vector<Eigen::Vector4f>& sums = first_.sums;
  last_voxels_ = sums.size();
  out.resize(sums.size());
  for (std::size_t i = 0; i < sums.size(); ++i) out[i] = sums[i].head<3>() / sums[i].w();
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
