#include "scfloam/features/feature_extractor.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "scfloam/error.hpp"
#include "scfloam/features/fast_atan.hpp"
#include "scfloam/xyz4.hpp"

namespace scfloam {

namespace {

constexpr std::size_t kMaxBeams = 128;  // the largest model (OS1-128)
constexpr int kMaxRingField = 1024;     // rings a ring field may number (larger values are dropped)

// fast_atan_unit (features/fast_atan.hpp): 6e-4 deg is far below the 1/3 deg beam spacing.
inline float elevation_deg(float z, float horizontal_range) {
  constexpr float kDeg = 180.0f / static_cast<float>(M_PI);
  const float az = std::abs(z);
  const float a = az <= horizontal_range
                      ? fast_atan_unit(az / horizontal_range)
                      : static_cast<float>(M_PI / 2) - fast_atan_unit(horizontal_range / az);
  return (z < 0 ? -a : a) * kDeg;
}

#if defined(__SSE2__)
// Per lane: mask ? a : b (SSE2 has no blend instruction).
inline __m128 select_ps(__m128 mask, __m128 a, __m128 b) {
  return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b));
}

// elevation_deg for four points: the same float operations in the same order (no FMA on
// baseline x86-64), so each lane equals the scalar value bit for bit.
inline __m128 elevation_deg4(__m128 z, __m128 horizontal_range) {
  const __m128 sign = _mm_set1_ps(-0.0f);
  const __m128 az = _mm_andnot_ps(sign, z);
  const __m128 below = _mm_cmple_ps(az, horizontal_range);  // az <= h: atan(az / h)
  const __m128 num = select_ps(below, az, horizontal_range);
  const __m128 den = select_ps(below, horizontal_range, az);
  const __m128 x = _mm_div_ps(num, den);
  const __m128 x2 = _mm_mul_ps(x, x);
  __m128 poly = _mm_add_ps(_mm_set1_ps(-0.0851330f), _mm_mul_ps(x2, _mm_set1_ps(0.0208351f)));
  poly = _mm_add_ps(_mm_set1_ps(0.1801410f), _mm_mul_ps(x2, poly));
  poly = _mm_add_ps(_mm_set1_ps(-0.3302995f), _mm_mul_ps(x2, poly));
  poly = _mm_add_ps(_mm_set1_ps(0.9998660f), _mm_mul_ps(x2, poly));
  const __m128 atan = _mm_mul_ps(x, poly);
  const __m128 above = _mm_sub_ps(_mm_set1_ps(static_cast<float>(M_PI / 2)), atan);
  __m128 a = select_ps(below, atan, above);
  a = _mm_or_ps(a, _mm_and_ps(z, sign));  // z < 0: -a (a >= 0; -0 keeps +0's value)
  return _mm_mul_ps(a, _mm_set1_ps(180.0f / static_cast<float>(M_PI)));
}

// ring_from_elevation_hdl64_deg of four elevations: the same float operations in the same
// order, so each lane equals the scalar ring.
inline __m128i hdl64_rings4(__m128 a) {
  const __m128i upper = _mm_cvttps_epi32(_mm_add_ps(
      _mm_mul_ps(_mm_sub_ps(_mm_set1_ps(2.0f), a), _mm_set1_ps(3.0f)), _mm_set1_ps(0.5f)));
  const __m128i lower = _mm_add_epi32(
      _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(_mm_sub_ps(_mm_set1_ps(-8.83f), a), _mm_set1_ps(2.0f)),
                                  _mm_set1_ps(0.5f))),
      _mm_set1_epi32(32));
  const __m128i in_upper = _mm_castps_si128(_mm_cmpge_ps(a, _mm_set1_ps(-8.83f)));
  const __m128i ring = _mm_or_si128(_mm_and_si128(in_upper, upper), _mm_andnot_si128(in_upper, lower));
  // Inside the field of view (not a > 2, not a < -24.33) and 0 <= ring < 64, else -1.
  const __m128 outside = _mm_or_ps(_mm_cmpgt_ps(a, _mm_set1_ps(2.0f)), _mm_cmplt_ps(a, _mm_set1_ps(-24.33f)));
  __m128i valid = _mm_andnot_si128(_mm_castps_si128(outside), _mm_cmpgt_epi32(ring, _mm_set1_epi32(-1)));
  valid = _mm_and_si128(valid, _mm_cmplt_epi32(ring, _mm_set1_epi32(64)));
  return _mm_or_si128(_mm_and_si128(valid, ring), _mm_andnot_si128(valid, _mm_set1_epi32(-1)));
}
#endif

}  // namespace

void correct_elevation(FeatureCloud& points, double angle_deg) {
  if (angle_deg == 0) return;
  const float c = static_cast<float>(std::cos(angle_deg * M_PI / 180.0));
  const float s = static_cast<float>(std::sin(angle_deg * M_PI / 180.0));
  std::size_t i = 0;
#if defined(__SSE2__)
  // Four points at a time, the scalar loop's operations in its order (equal bit for bit).
  const __m128 c4 = _mm_set1_ps(c), s4 = _mm_set1_ps(s), tiny = _mm_set1_ps(1e-3f);
  for (; i + 4 <= points.size(); i += 4) {
    float* q = points[i].data();  // four points, 12 floats in a row
    __m128 x, y, z;
    load_xyz4(q, x, y, z);
    const __m128 h = _mm_sqrt_ps(_mm_add_ps(_mm_mul_ps(x, x), _mm_mul_ps(y, y)));
    const __m128 keep = _mm_cmplt_ps(h, tiny);  // on the axis: left alone
    const __m128 scale = _mm_div_ps(_mm_sub_ps(_mm_mul_ps(h, c4), _mm_mul_ps(z, s4)), h);
    const __m128 nz = _mm_add_ps(_mm_mul_ps(z, c4), _mm_mul_ps(h, s4));
    store_xyz4(q, select_ps(keep, x, _mm_mul_ps(x, scale)), select_ps(keep, y, _mm_mul_ps(y, scale)),
               select_ps(keep, z, nz));
  }
#endif
  for (; i < points.size(); ++i) {
    Eigen::Vector3f& p = points[i];
    const float horizontal = std::sqrt(p.x() * p.x() + p.y() * p.y());
    if (horizontal < 1e-3f) continue;
    const float new_horizontal = horizontal * c - p.z() * s;
    p.z() = p.z() * c + horizontal * s;
    p.x() *= new_horizontal / horizontal;
    p.y() *= new_horizontal / horizontal;
  }
}

namespace {

// The curvature of point i from the sums of its offsets to the hw points on either side. Only
// the part across the chord from the left to the right neighbours counts. Along the chord,
// the sum measures uneven spacing, not shape: a dropped return on smooth ground shifts one
// side's mean by a spacing, which at 30 m passes the edge threshold, and those ring-bound
// "edges" pull the pose back to the last frame's (docs/degenerate.md).
inline float curvature_across_chord(float lx, float ly, float lz, float rx, float ry, float rz) {
  float dx = lx + rx, dy = ly + ry, dz = lz + rz;
  const float cx = rx - lx, cy = ry - ly, cz = rz - lz;
  const float c2 = cx * cx + cy * cy + cz * cz;
  const float f = c2 > 0 ? (dx * cx + dy * cy + dz * cz) / c2 : 0.f;
  dx -= f * cx;
  dy -= f * cy;
  dz -= f * cz;
  return dx * dx + dy * dy + dz * dz;
}

}  // namespace

// A ring's curvatures come in no order: std::nth_element's compare branches mispredicted about
// half the time (perf: a fifth of select_in_ring).
float kth_smallest(float* v, int n, int k) {
  int lo = 0, hi = n;  // v[lo, hi) holds the answer
  while (hi - lo > 16) {
    const float a = v[lo], b = v[lo + (hi - lo) / 2], c = v[hi - 1];
    const float pivot = std::max(std::min(a, b), std::min(std::max(a, b), c));  // median of three
    if (!(pivot == pivot)) return pivot;  // NaN (curvatures have none): no partition could progress
    // v[lo, less) < pivot, then v[less, equal) == pivot: every swap is made, the cursor
    // advances by the comparison.
    int less = lo;
    for (int i = lo; i < hi; ++i) {
      const float x = v[i];
      v[i] = v[less];
      v[less] = x;
      less += static_cast<int>(x < pivot);
    }
    int equal = less;
    for (int i = less; i < hi; ++i) {
      const float x = v[i];
      v[i] = v[equal];
      v[equal] = x;
      equal += static_cast<int>(x == pivot);
    }
    if (k < less) hi = less;
    else if (k < equal) return pivot;  // never empty: the pivot is one of the values
    else lo = equal;
  }
  std::sort(v + lo, v + hi);
  return v[k];
}

void ring_curvature(const Eigen::Vector3f* p, int n, int hw, float* curvature) {
  std::fill(curvature, curvature + n, 0.f);
  if (n < 2 * hw + 1) return;
  // Sums of the offsets p_j - p_i, in float: offsets between neighbours keep their precision
  // at any range (float sums of the positions themselves lose centimetres at 90 m). The ring
  // is copied to structure-of-arrays so that four consecutive points go through SSE2 at once;
  // the scalar tail does the same float operations in the same order, so a point's value does
  // not depend on where it falls.
  thread_local std::vector<float> buffer;
  buffer.resize(3 * static_cast<std::size_t>(n));
  float* x = buffer.data();
  float* y = x + n;
  float* z = y + n;
  for (int i = 0; i < n; ++i) {
    x[i] = p[i].x();
    y[i] = p[i].y();
    z[i] = p[i].z();
  }
  int i = hw;
#if defined(__SSE2__)
  const __m128 zero = _mm_setzero_ps();
  for (; i + 4 <= n - hw; i += 4) {
    const __m128 px = _mm_loadu_ps(x + i), py = _mm_loadu_ps(y + i), pz = _mm_loadu_ps(z + i);
    __m128 lx = zero, ly = zero, lz = zero, rx = zero, ry = zero, rz = zero;
    for (int j = 1; j <= hw; ++j) {
      lx = _mm_add_ps(lx, _mm_sub_ps(_mm_loadu_ps(x + i - j), px));
      ly = _mm_add_ps(ly, _mm_sub_ps(_mm_loadu_ps(y + i - j), py));
      lz = _mm_add_ps(lz, _mm_sub_ps(_mm_loadu_ps(z + i - j), pz));
      rx = _mm_add_ps(rx, _mm_sub_ps(_mm_loadu_ps(x + i + j), px));
      ry = _mm_add_ps(ry, _mm_sub_ps(_mm_loadu_ps(y + i + j), py));
      rz = _mm_add_ps(rz, _mm_sub_ps(_mm_loadu_ps(z + i + j), pz));
    }
    __m128 dx = _mm_add_ps(lx, rx), dy = _mm_add_ps(ly, ry), dz = _mm_add_ps(lz, rz);
    const __m128 cx = _mm_sub_ps(rx, lx), cy = _mm_sub_ps(ry, ly), cz = _mm_sub_ps(rz, lz);
    const __m128 c2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(cx, cx), _mm_mul_ps(cy, cy)), _mm_mul_ps(cz, cz));
    const __m128 dot = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, cx), _mm_mul_ps(dy, cy)), _mm_mul_ps(dz, cz));
    // f = c2 > 0 ? dot / c2 : 0 (the division's NaN in a masked-off lane is discarded).
    const __m128 f = _mm_and_ps(_mm_cmpgt_ps(c2, zero), _mm_div_ps(dot, c2));
    dx = _mm_sub_ps(dx, _mm_mul_ps(f, cx));
    dy = _mm_sub_ps(dy, _mm_mul_ps(f, cy));
    dz = _mm_sub_ps(dz, _mm_mul_ps(f, cz));
    _mm_storeu_ps(curvature + i, _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz)));
  }
#endif
  for (; i < n - hw; ++i) {
    float lx = 0, ly = 0, lz = 0, rx = 0, ry = 0, rz = 0;
    for (int j = 1; j <= hw; ++j) {
      lx += x[i - j] - x[i];
      ly += y[i - j] - y[i];
      lz += z[i - j] - z[i];
      rx += x[i + j] - x[i];
      ry += y[i + j] - y[i];
      rz += z[i + j] - z[i];
    }
    curvature[i] = curvature_across_chord(lx, ly, lz, rx, ry, rz);
  }
}

FeatureExtractor::FeatureExtractor(const PreprocessConfig& preprocess, const RingConfig& rings,
                                   const FeatureConfig& features)
    : pre_(preprocess),
      feat_(features),
      model_(rings.lidar == "auto" ? LidarModel::hdl64 : parse_lidar_model(rings.lidar)),
      auto_layout_(rings.lidar == "auto"),
      adopt_learned_(rings.adopt_learned_layout),
      min_points_per_ring_(rings.min_points_per_ring),
      // "auto": room for any ring field until a layout is learned.
      beams_(auto_layout_ ? static_cast<int>(kMaxBeams) : num_beams(model_)),
      plane_inv_leaf_(static_cast<float>(1.0 / features.plane_leaf_m)) {
  if (features.curvature_half_window < 1) throw Error("features: curvature_half_window must be >= 1");
  if (features.sectors_per_ring < 1) throw Error("features: sectors_per_ring must be >= 1");
  if (!(features.edge_leaf_m > 0) || !(features.plane_leaf_m > 0))
    throw Error("features: edge_leaf_m and plane_leaf_m must be positive");
  resize_rings(beams_);
  if (auto_layout_) layout_info_.source = "none";  // until a scan has taught the beams
  layout_info_.beams = beams_;
}

void FeatureExtractor::resize_rings(int beams) {
  beams_ = beams;
  ring_begin_.resize(beams_ + 1);
  candidates_.resize(beams_);
  ring_edges_.resize(beams_);
  noise_scratch_.resize(beams_);
  ring_planes_.resize(beams_);
  ring_plane_runs_.resize(beams_);
  ring_resorted_.resize(beams_);
  sort_scratch_.resize(beams_);
  ring_copy_.resize(beams_);
}

void FeatureExtractor::decide_layout(const std::vector<LidarPoint>& points) {
  const BeamLayout layout = learn_beam_layout(points, pre_.min_range_m, pre_.max_range_m);
  if (layout.points_used < kMinLayoutPoints) return;  // decide on a fuller scan
  layout_decided_ = true;
  char text[256];
  if (auto_layout_) {
    if (!layout.confident) {
      std::snprintf(text, sizeof text,
                    "rings.lidar is auto, but the first scan's elevations do not form distinct beams "
                    "(%.0f %% of %d returns near %zu elevation peaks, 90 %% needed): set rings.lidar "
                    "(--sensor) to the sensor's model",
                    100.0 * layout.clustered_fraction, layout.points_used, layout.elevations_deg.size());
      throw Error(text);
    }
    std::snprintf(text, sizeof text, "rings.lidar is auto");
  } else {
    if (!layout.confident) return;
    const TableFit fit = check_table_fit(model_, layout);
    layout_info_.scan_beams = static_cast<int>(layout.elevations_deg.size());
    layout_info_.cropped_beams = fit.dropped_beams;
    layout_info_.cropped_fraction = fit.dropped_fraction;
    if (fit.fits || !adopt_learned_) return;
    std::snprintf(text, sizeof text,
                  "the %s ring table does not fit the scans' %zu beams (%d share a ring, %d lie "
                  "outside its field of view)",
                  lidar_model_name(model_), layout.elevations_deg.size(), fit.merged_beams, fit.dropped_beams);
  }
  learned_.emplace(layout.elevations_deg);
  resize_rings(learned_->beams());
  layout_info_.source = "learned";
  layout_info_.beams = beams_;
  layout_info_.highest_deg = layout.elevations_deg.front();
  layout_info_.lowest_deg = layout.elevations_deg.back();
  layout_info_.reason = text;
}

void FeatureExtractor::assign_rings(const std::vector<LidarPoint>& points, bool use_ring_field) {
  const std::size_t n = points.size();
  ring_of_.resize(n);
  const float min_r2 = static_cast<float>(pre_.min_range_m * pre_.min_range_m);
  const float max_r2 = static_cast<float>(pre_.max_range_m * pre_.max_range_m);
  // A stable counting sort by ring, in parallel: each fixed block counts its rings, a prefix
  // over (ring, block) gives every block its write offsets, and each block scatters its points
  // in input (acquisition) order. Fixed blocks keep the result independent of the scheduler.
  constexpr std::size_t kBlock = 8192;
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  const std::size_t R = static_cast<std::size_t>(beams_);
  block_counts_.assign(blocks * R, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks, 1), [&](const auto& range) {
    for (std::size_t b = range.begin(); b != range.end(); ++b) {
      int* counts = block_counts_.data() + b * R;
      std::size_t i = b * kBlock;
      const std::size_t e = std::min(n, i + kBlock);
#if defined(__SSE2__)
      if (!use_ring_field && R <= kMaxBeams) {
        // Four points at a time through the square root, division and atan; the lanes equal
        // the scalar loop's values below, so the rings do not depend on the block layout.
        const __m128 min4 = _mm_set1_ps(min_r2), max4 = _mm_set1_ps(max_r2), zero = _mm_setzero_ps();
        const __m128 outside = _mm_set1_ps(90.0f);  // an elevation no model has a ring for
        alignas(16) float elevation[4];
        // Counts with a slot for "no ring" in front, so that counting needs no branch on the
        // ring's sign; one histogram per lane: consecutive points mostly share a ring, and
        // one counter incremented point after point waits on its own last store each time.
        std::array<std::array<int, kMaxBeams + 1>, 4> local{};
        alignas(16) int rings[4];
        for (; i + 4 <= e; i += 4) {
          const LidarPoint* q = points.data() + i;
          const __m128 x = _mm_setr_ps(q[0].x, q[1].x, q[2].x, q[3].x);
          const __m128 y = _mm_setr_ps(q[0].y, q[1].y, q[2].y, q[3].y);
          const __m128 z = _mm_setr_ps(q[0].z, q[1].z, q[2].z, q[3].z);
          const __m128 r2 = _mm_add_ps(_mm_mul_ps(x, x), _mm_mul_ps(y, y));
          // v - v is 0 for a finite v and NaN for inf or NaN.
          __m128 ok = _mm_and_ps(_mm_cmpeq_ps(_mm_sub_ps(x, x), zero), _mm_cmpeq_ps(_mm_sub_ps(y, y), zero));
          ok = _mm_and_ps(ok, _mm_cmpeq_ps(_mm_sub_ps(z, z), zero));
          ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpgt_ps(r2, zero), _mm_cmpge_ps(r2, min4)));
          ok = _mm_and_ps(ok, _mm_cmple_ps(r2, max4));
          const __m128 el = elevation_deg4(z, _mm_sqrt_ps(r2));
          const __m128 a = select_ps(ok, el, outside);
          __m128i ring4;
          if (!learned_ && model_ == LidarModel::hdl64) {
            ring4 = hdl64_rings4(a);
            _mm_store_si128(reinterpret_cast<__m128i*>(rings), ring4);
          } else {
            _mm_store_ps(elevation, a);
            for (int lane = 0; lane < 4; ++lane)
              rings[lane] = learned_ ? learned_->ring(elevation[lane]) : ring_from_elevation_deg(model_, elevation[lane]);
            ring4 = _mm_load_si128(reinterpret_cast<const __m128i*>(rings));
          }
          // Rings (-1..127) fit int16: four stored at once.
          _mm_storel_epi64(reinterpret_cast<__m128i*>(ring_of_.data() + i), _mm_packs_epi32(ring4, ring4));
          for (int lane = 0; lane < 4; ++lane) ++local[lane][static_cast<std::size_t>(rings[lane] + 1)];
        }
        for (std::size_t r = 0; r < R; ++r) counts[r] += local[0][r + 1] + local[1][r + 1] + local[2][r + 1] + local[3][r + 1];
      }
#endif
      for (; i != e; ++i) {
        const LidarPoint& p = points[i];
        const float r2 = p.x * p.x + p.y * p.y;
        std::int16_t ring = -1;
        if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && r2 > 0 &&
            r2 >= min_r2 && r2 <= max_r2) {
          if (use_ring_field) {
            ring = (p.ring >= 0 && p.ring < beams_) ? p.ring : -1;
          } else {
            const float a = elevation_deg(p.z, std::sqrt(r2));
            ring = static_cast<std::int16_t>(learned_                         ? learned_->ring(a)
                                             : model_ == LidarModel::hdl64 ? ring_from_elevation_hdl64_deg(a)
                                                                           : ring_from_elevation_deg(model_, a));
          }
        }
        ring_of_[i] = ring;
        if (ring >= 0) ++counts[ring];
      }
    }
  });
  // Turn counts into write offsets, ring-major: ring r's points from block 0, then block 1, ...
  int offset = 0;
  for (std::size_t r = 0; r < R; ++r) {
    ring_begin_[r] = offset;
    for (std::size_t b = 0; b < blocks; ++b) {
      const int count = block_counts_[b * R + r];
      block_counts_[b * R + r] = offset;
      offset += count;
    }
  }
  ring_begin_[R] = offset;
  ordered_.resize(static_cast<std::size_t>(offset));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks, 1), [&](const auto& range) {
    for (std::size_t b = range.begin(); b != range.end(); ++b) {
      int* cursor = block_counts_.data() + b * R;
      for (std::size_t i = b * kBlock, e = std::min(n, i + kBlock); i != e; ++i)
        if (ring_of_[i] >= 0)
          ordered_[cursor[ring_of_[i]]++] = Eigen::Vector3f(points[i].x, points[i].y, points[i].z);
    }
  });
}

void FeatureExtractor::order_ring_by_azimuth(int ring) {
  Eigen::Vector3f* p = ordered_.data() + ring_begin_[ring];
  const int n = ring_begin_[ring + 1] - ring_begin_[ring];
  // Acquisition order is azimuth order for spinning sensors; check the turning direction of
  // consecutive points and only sort rings that are out of order (e.g. merged packets).
  int forward = 0, backward = 0;
  for (int i = 0; i + 1 < n; ++i) {
    const float cross = p[i].x() * p[i + 1].y() - p[i].y() * p[i + 1].x();
    (cross > 0 ? forward : backward) += 1;
  }
  ring_resorted_[ring] = 0;
  if (std::min(forward, backward) <= n / 50) return;
  ring_resorted_[ring] = 1;
  auto& order = sort_scratch_[ring];
  order.resize(n);
  for (int i = 0; i < n; ++i) order[i] = {std::atan2(p[i].y(), p[i].x()), i};
  std::sort(order.begin(), order.end());
  FeatureCloud& copy = ring_copy_[ring];
  copy.assign(p, p + n);
  for (int i = 0; i < n; ++i) p[i] = copy[order[i].second];
}

void FeatureExtractor::select_in_ring(int ring) {
  FeatureCloud& edges = ring_edges_[ring];
  FeatureCloud& planes = ring_planes_[ring];
  VoxelRuns& plane_runs = ring_plane_runs_[ring];
  edges.clear();
  planes.clear();
  plane_runs.clear();
  const int begin = ring_begin_[ring];
  const int n = ring_begin_[ring + 1] - begin;
  const int hw = feat_.curvature_half_window;
  if (n < min_points_per_ring_ || n < 2 * hw + 1 + feat_.sectors_per_ring) return;
  const Eigen::Vector3f* p = ordered_.data() + begin;
  float* curv = curvature_.data() + begin;
  char* picked = picked_.data() + begin;
  char* unreliable = unreliable_.data() + begin;
  ring_curvature(p, n, hw, curv);
  std::fill(picked, picked + n, 0);
  std::fill(unreliable, unreliable + n, 0);
  if (feat_.reject_occluded) {
    // LOAM's occlusion test: at a depth jump between neighbours seen at the same bearing, the
    // far side's points are hidden or revealed as the sensor moves: never edges. LOAM's test,
    // |q - p d_q / d_p| / d_q < ratio for the far point p and the near q (either way round),
    // is |p / d_p - q / d_q| < ratio: the two bearings lie within an angle whose chord is
    // `ratio`, i.e. p.q > (1 - ratio^2 / 2) d_p d_q. Squared, it needs no root or division.
    const float ratio = static_cast<float>(feat_.occlusion_gap_ratio);
    const float cos_min = 1.0f - 0.5f * ratio * ratio;
    const float cos_min2 = cos_min * cos_min;
    // ratio >= sqrt(2) makes cos_min <= 0, where squaring would lose the sign: use the roots.
    const bool wide = !(cos_min > 0);
    for (int i = hw; i < n - hw - 1; ++i) {
      if ((p[i + 1] - p[i]).squaredNorm() <= 0.1f) continue;
      const float dot = p[i].dot(p[i + 1]);
      const float n1 = p[i].squaredNorm(), n2 = p[i + 1].squaredNorm();
      const bool same_bearing = wide ? dot > cos_min * std::sqrt(n1 * n2)
                                     : dot > 0 && dot * dot > cos_min2 * (n1 * n2);
      if (!same_bearing) continue;
      if (n1 > n2) {
        for (int k = std::max(0, i - hw); k <= i; ++k) unreliable[k] = 1;
      } else {
        for (int k = i + 1; k <= std::min(n - 1, i + hw + 1); ++k) unreliable[k] = 1;
      }
    }
  }
  float threshold = static_cast<float>(feat_.edge_min_curvature);
  if (feat_.edge_noise_factor > 0) {
    // The median of every 4th point: as good an estimate of the noise level, 4x cheaper.
    std::vector<float>& sorted = noise_scratch_[ring];
    sorted.clear();
    for (int i = hw; i < n - hw; i += 4) sorted.push_back(curv[i]);
    const float median = kth_smallest(sorted.data(), static_cast<int>(sorted.size()), static_cast<int>(sorted.size() / 2));
    threshold = std::max(threshold, static_cast<float>(feat_.edge_noise_factor) * median);
  }
  const float gap2 = static_cast<float>(feat_.suppression_gap_m * feat_.suppression_gap_m);
  const int sectors = feat_.sectors_per_ring;
  const int usable = n - 2 * hw;
  std::vector<int>& cand = candidates_[ring];
  // Plane points are written without a branch: every point goes in, the count advances only
  // for the ones not picked as (or next to) an edge.
  planes.resize(static_cast<std::size_t>(usable));
  std::size_t plane_count = 0;
  for (int s = 0; s < sectors; ++s) {
    const int sb = hw + usable * s / sectors, se = hw + usable * (s + 1) / sectors;
    // Candidates without a branch per point: every index is written, the count advances
    // only for a candidate (callgrind's branch model: 16 % fewer mispredictions here).
    cand.resize(static_cast<std::size_t>(se - sb));
    int count = 0;
    for (int i = sb; i < se; ++i) {
      cand[count] = i;
      count += static_cast<int>(curv[i] > threshold) & static_cast<int>(!unreliable[i]);
    }
    cand.resize(static_cast<std::size_t>(count));
    // Strongest first (ties by position, so the order is fully defined). Only the first few
    // are ever looked at (max_edges_per_sector, plus those suppressed by an earlier pick):
    // order a head of the list, and the rest only if the head runs out.
    const auto stronger = [&](int a, int b) { return curv[a] > curv[b] || (curv[a] == curv[b] && a < b); };
    const std::size_t head = std::min(cand.size(), static_cast<std::size_t>(4 * feat_.max_edges_per_sector + 8));
    std::partial_sort(cand.begin(), cand.begin() + static_cast<std::ptrdiff_t>(head), cand.end(), stronger);
    int chosen = 0;
    for (std::size_t c = 0; c < cand.size(); ++c) {
      if (chosen >= feat_.max_edges_per_sector) break;
      if (c == head) std::sort(cand.begin() + static_cast<std::ptrdiff_t>(head), cand.end(), stronger);
      const int i = cand[c];
      if (picked[i]) continue;
      edges.push_back(p[i]);
      ++chosen;
      picked[i] = 1;
      for (int k = 1; k <= hw && i + k < n; ++k) {
        if ((p[i + k] - p[i + k - 1]).squaredNorm() > gap2) break;
        picked[i + k] = 1;
      }
      for (int k = 1; k <= hw && i - k >= 0; ++k) {
        if ((p[i - k] - p[i - k + 1]).squaredNorm() > gap2) break;
        picked[i - k] = 1;
      }
    }
    for (int i = sb; i < se; ++i) {
      planes[plane_count] = p[i];
      plane_count += static_cast<std::size_t>(!picked[i]);
    }
  }
  planes.resize(plane_count);
  correct_elevation(edges, pre_.elevation_correction_deg);
  correct_elevation(planes, pre_.elevation_correction_deg);
  plane_runs.append(planes.data(), planes.data() + planes.size(), plane_inv_leaf_);
}

void FeatureExtractor::extract(const std::vector<LidarPoint>& points, bool use_ring_field,
                               FeatureCloud& edges, FeatureCloud& planes) {
  extract(points, use_ring_field, edges, &planes);
}

void FeatureExtractor::extract(const std::vector<LidarPoint>& points, bool use_ring_field,
                               FeatureCloud& edges, FeatureCloud* planes) {
  stats_ = FeatureStats{};
  stats_.input_points = static_cast<int>(points.size());
  if (use_ring_field) {
    // The ring field decides how many rings there are: a 32-beam driver's rings under a
    // 16-beam preset would otherwise lose rings 16-31 (values beyond kMaxRingField are dropped).
    int highest = -1;
    for (const LidarPoint& p : points) highest = std::max(highest, static_cast<int>(p.ring));
    if (highest >= beams_) resize_rings(std::min(highest, kMaxRingField - 1) + 1);
    layout_info_.source = "ring field";
    layout_info_.beams = beams_;
  } else if (!layout_decided_) {
    decide_layout(points);
    if (auto_layout_ && !learned_) {
      // Too few returns to learn the beams from yet: no features from this scan.
      edges.clear();
      if (planes) planes->clear();
      for (VoxelRuns& runs : ring_plane_runs_) runs.clear();
      return;
    }
  }
  assign_rings(points, use_ring_field);
  stats_.kept_points = static_cast<int>(ordered_.size());
  curvature_.resize(ordered_.size());
  picked_.resize(ordered_.size());
  unreliable_.resize(ordered_.size());
  // Rings are independent: order and select each in parallel (per-ring scratch buffers).
  tbb::parallel_for(tbb::blocked_range<int>(0, beams_, 1), [&](const auto& range) {
    for (int r = range.begin(); r != range.end(); ++r) {
      order_ring_by_azimuth(r);
      select_in_ring(r);
    }
  });
  // Rings concatenated in ring order, each copied in parallel to its place.
  std::vector<std::size_t>& edge_at = concat_edges_;
  std::vector<std::size_t>& plane_at = concat_planes_;
  edge_at.assign(static_cast<std::size_t>(beams_) + 1, 0);
  plane_at.assign(static_cast<std::size_t>(beams_) + 1, 0);
  for (int r = 0; r < beams_; ++r) {
    stats_.rings_resorted += ring_resorted_[r];
    if (!ring_edges_[r].empty() || !ring_planes_[r].empty()) ++stats_.rings_used;
    edge_at[r + 1] = edge_at[r] + ring_edges_[r].size();
    plane_at[r + 1] = plane_at[r] + ring_planes_[r].size();
  }
  edges.resize(edge_at[beams_]);
  if (planes) planes->resize(plane_at[beams_]);
  tbb::parallel_for(tbb::blocked_range<int>(0, beams_, 4), [&](const auto& range) {
    for (int r = range.begin(); r != range.end(); ++r) {
      std::copy(ring_edges_[r].begin(), ring_edges_[r].end(), edges.begin() + static_cast<std::ptrdiff_t>(edge_at[r]));
      if (planes)
        std::copy(ring_planes_[r].begin(), ring_planes_[r].end(),
                  planes->begin() + static_cast<std::ptrdiff_t>(plane_at[r]));
    }
  });
}

}  // namespace scfloam
