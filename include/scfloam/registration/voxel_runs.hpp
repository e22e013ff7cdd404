// Runs of consecutive points that share a voxel, summed: the first step of the voxel filter,
// header-only so that the feature extractor can take it inside its parallel per-ring pass.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "scfloam/registration/voxel_hash.hpp"
#include "scfloam/xyz4.hpp"

namespace scfloam {

// Calls emit(key, sum) for each run of consecutive points in one voxel (1 / inv wide), sum =
// (x, y, z sums, count). Feature clouds come ring by ring in azimuth order, so a voxel's
// points arrive in a few long runs: the sums stay in registers for a run and the caller's
// table is probed only when the voxel changes. (Scalar sums: building an Eigen::Vector4f per
// point from x, y, z, 1 went through the stack and stalled on a failed store-to-load forward,
// ~25 ns a point.)
template <typename Emit>
void for_each_voxel_run(const Eigen::Vector3f* begin, const Eigen::Vector3f* end, float inv, Emit emit) {
  std::uint64_t run_key = 0;
  float sx = 0, sy = 0, sz = 0, count = 0;
  const auto add = [&](const Eigen::Vector3f& p, std::uint64_t key) {
    if (key != run_key) {
      if (count != 0) emit(run_key, Eigen::Vector4f(sx, sy, sz, count));
      run_key = key;
      sx = sy = sz = count = 0;
    }
    sx += p.x();
    sy += p.y();
    sz += p.z();
    count += 1;
  };
  const Eigen::Vector3f* p = begin;
#if defined(__SSE2__)
  // The voxel coordinates of four points at a time (the same float operations as
  // voxel_coords, so the same voxels); the runs then go point by point.
  const __m128 inv4 = _mm_set1_ps(inv);
  alignas(16) std::int32_t ix[4], iy[4], iz[4];
  for (; end - p >= 4; p += 4) {
    __m128 x, y, z;
    load_xyz4(p->data(), x, y, z);
    _mm_store_si128(reinterpret_cast<__m128i*>(ix), floor4(_mm_mul_ps(x, inv4)));
    _mm_store_si128(reinterpret_cast<__m128i*>(iy), floor4(_mm_mul_ps(y, inv4)));
    _mm_store_si128(reinterpret_cast<__m128i*>(iz), floor4(_mm_mul_ps(z, inv4)));
    for (int k = 0; k < 4; ++k) add(p[k], voxel_key(ix[k], iy[k], iz[k]));
  }
#endif
  for (; p != end; ++p) {
    const Eigen::Vector3i c = voxel_coords(*p, inv);
    add(*p, voxel_key(c.x(), c.y(), c.z()));
  }
  if (count != 0) emit(run_key, Eigen::Vector4f(sx, sy, sz, count));
}

// The runs of some points, kept: a filter fed runs probes its table once per run.
struct VoxelRuns {
  std::vector<std::uint64_t> keys;    // voxel_key of each run
  std::vector<Eigen::Vector4f> sums;  // xyz sum, count
  void clear() {
    keys.clear();
    sums.clear();
  }
  void append(const Eigen::Vector3f* begin, const Eigen::Vector3f* end, float inv) {
    for_each_voxel_run(begin, end, inv, [this](std::uint64_t key, const Eigen::Vector4f& sum) {
      keys.push_back(key);
      sums.push_back(sum);
    });
  }
};

}  // namespace scfloam
