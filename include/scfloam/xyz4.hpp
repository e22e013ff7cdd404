// Four consecutive Eigen::Vector3f (x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3 in memory) to and
// from one SSE2 register per coordinate, in three loads or stores and some shuffles: gathering
// lane by lane costs twelve scalar loads, and storing through a buffer stalls on store
// forwarding. Only where the target has SSE2 (every x86-64); callers keep a scalar path.
#pragma once

#if defined(__SSE2__)
#include <emmintrin.h>

#include <Eigen/Core>

namespace scfloam {

static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float), "points are packed x y z");

inline void load_xyz4(const float* q, __m128& x, __m128& y, __m128& z) {
  const __m128 a = _mm_loadu_ps(q), b = _mm_loadu_ps(q + 4), c = _mm_loadu_ps(q + 8);
  x = _mm_shuffle_ps(a, _mm_shuffle_ps(b, c, _MM_SHUFFLE(1, 1, 2, 2)), _MM_SHUFFLE(2, 0, 3, 0));
  y = _mm_shuffle_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(0, 0, 1, 1)), _mm_shuffle_ps(b, c, _MM_SHUFFLE(2, 2, 3, 3)),
                     _MM_SHUFFLE(2, 0, 2, 0));
  z = _mm_shuffle_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(1, 1, 2, 2)), _mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 3, 0, 0)),
                     _MM_SHUFFLE(2, 0, 2, 0));
}

inline void store_xyz4(float* q, __m128 x, __m128 y, __m128 z) {
  _mm_storeu_ps(q, _mm_shuffle_ps(_mm_shuffle_ps(x, y, _MM_SHUFFLE(0, 0, 0, 0)),
                                  _mm_shuffle_ps(z, x, _MM_SHUFFLE(1, 1, 0, 0)), _MM_SHUFFLE(2, 0, 2, 0)));
  _mm_storeu_ps(q + 4, _mm_shuffle_ps(_mm_shuffle_ps(y, z, _MM_SHUFFLE(1, 1, 1, 1)),
                                      _mm_shuffle_ps(x, y, _MM_SHUFFLE(2, 2, 2, 2)), _MM_SHUFFLE(2, 0, 2, 0)));
  _mm_storeu_ps(q + 8, _mm_shuffle_ps(_mm_shuffle_ps(z, x, _MM_SHUFFLE(3, 3, 2, 2)),
                                      _mm_shuffle_ps(y, z, _MM_SHUFFLE(3, 3, 3, 3)), _MM_SHUFFLE(2, 0, 2, 0)));
}

// floor() of four floats with |x| < 2^31, as floor_to_int (voxel_hash.hpp) does one.
inline __m128i floor4(__m128 v) {
  const __m128i i = _mm_cvttps_epi32(v);  // toward zero
  return _mm_add_epi32(i, _mm_castps_si128(_mm_cmplt_ps(v, _mm_cvtepi32_ps(i))));  // -1 below
}

}  // namespace scfloam
#endif
