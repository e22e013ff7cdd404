// F-LOAM feature extraction: range crop, rings, curvature per ring, edge selection per sector
// with neighbour suppression; the remaining points are plane points, and both get the
// preprocess config's elevation correction. Output is not yet
// voxel-downsampled (the odometry does that with registration/voxel_filter.hpp).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "scfloam/config.hpp"
#include "scfloam/features/beam_layout.hpp"
#include "scfloam/features/rings.hpp"
#include "scfloam/registration/voxel_runs.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

// Curvature of each point of one ring in F-LOAM's unit: squared norm of d = (sum of the
// 2*half_window neighbours - 2*half_window * p), keeping only d's part perpendicular to the
// chord between the means of the neighbours before and after p (so uneven spacing, as from a
// dropped return, is not curvature; on evenly spaced points it is F-LOAM's value). Points
// within half_window of either end get 0.
void ring_curvature(const Eigen::Vector3f* points, int n, int half_window, float* curvature);

// The k-th smallest of v[0, n) (0 <= k < n; v is reordered): the value std::nth_element finds,
// by a quickselect whose partitions have no data-dependent branches (a ring's noise level).
// Values must not be NaN (one that is may come back as the answer).
float kth_smallest(float* v, int n, int k);

// Rotates each point up by `angle_deg` in its own vertical plane (KITTI's beams read ~0.22 deg
// low); 0 leaves the points alone. Applied after ring assignment, which reads the sensor's own
// elevations.
void correct_elevation(FeatureCloud& points, double angle_deg);

struct FeatureStats {
  int input_points = 0;
  int kept_points = 0;  // after crop and ring assignment
  int rings_used = 0;
  int rings_resorted = 0;  // rings that were not in azimuth order and had to be sorted
};

// Where the rings came from: "table" (rings.lidar's elevation table), "learned" (the beam
// elevations of the first full scan, src/features/beam_layout.cpp), "ring field", or "none"
// (rings.lidar "auto" before a scan had enough returns to learn from).
struct RingLayoutInfo {
  std::string source = "table";
  int beams = 0;
  double highest_deg = 0, lowest_deg = 0;  // learned layouts
  std::string reason;                      // why a learned layout replaced the table
  // Tables kept on scans whose beams were learned: the beams learned, and those outside the
  // table's field of view (not used) with their share of the returns.
  int scan_beams = 0, cropped_beams = 0;
  double cropped_fraction = 0;
};

class FeatureExtractor {
 public:
  FeatureExtractor(const PreprocessConfig& preprocess, const RingConfig& rings,
                   const FeatureConfig& features);

  // `use_ring_field`: take LidarPoint::ring (the scan has rings and the config allows it).
  // Buffers persist between calls: steady-state use allocates nothing.
  void extract(const std::vector<LidarPoint>& points, bool use_ring_field, FeatureCloud& edges,
               FeatureCloud& planes);
  // The same, with `planes` == nullptr when only plane_runs() is wanted (no copy of ~100k
  // plane points into one cloud).
  void extract(const std::vector<LidarPoint>& points, bool use_ring_field, FeatureCloud& edges,
               FeatureCloud* planes);
  // After extract(): each ring's planes, in ring order, as runs of points in one
  // features.plane_leaf_m voxel, summed in the parallel per-ring pass while the points are in
  // cache. VoxelFilter::filter_runs makes them the downsampled planes with no pass over the
  // points: the same centroids as VoxelFilter::filter of the planes, up to rounding.
  const std::vector<VoxelRuns>& plane_runs() const { return ring_plane_runs_; }
  const FeatureStats& stats() const { return stats_; }
  void set_elevation_correction_deg(double deg) { pre_.elevation_correction_deg = deg; }
  const RingLayoutInfo& ring_layout() const { return layout_info_; }

 private:
  // Once, on the first scan without a ring field that has enough returns: learn the beams;
  // with rings.lidar "auto" use them, else use them only where the table does not fit.
  void decide_layout(const std::vector<LidarPoint>& points);
  void resize_rings(int beams);
  void assign_rings(const std::vector<LidarPoint>& points, bool use_ring_field);
  void order_ring_by_azimuth(int ring);
  void select_in_ring(int ring);

  PreprocessConfig pre_;
  FeatureConfig feat_;
  LidarModel model_;
  bool auto_layout_;         // rings.lidar == "auto"
  bool adopt_learned_;       // rings.adopt_learned_layout
  bool layout_decided_ = false;
  std::optional<LearnedRingTable> learned_;
  RingLayoutInfo layout_info_;
  int min_points_per_ring_;
  int beams_;

  std::vector<std::int16_t> ring_of_;        // per input point, -1 = dropped
  std::vector<int> ring_begin_;              // offsets into ordered_ (beams_ + 1)
  std::vector<int> block_counts_;            // per (input block, ring): count, then cursor
  std::vector<Eigen::Vector3f> ordered_;     // kept points grouped by ring
  std::vector<float> curvature_;
  std::vector<char> picked_, unreliable_;
  std::vector<std::vector<int>> candidates_;     // per ring scratch
  std::vector<std::vector<float>> noise_scratch_;  // per ring: curvatures for the median
  std::vector<FeatureCloud> ring_edges_, ring_planes_;
  std::vector<VoxelRuns> ring_plane_runs_;
  float plane_inv_leaf_;                                       // 1 / features.plane_leaf_m
  std::vector<char> ring_resorted_;                            // per ring, last extract()
  std::vector<std::vector<std::pair<float, int>>> sort_scratch_;  // per ring
  std::vector<FeatureCloud> ring_copy_;                        // per ring
  std::vector<std::size_t> concat_edges_, concat_planes_;      // per ring: output offsets
  FeatureStats stats_;
};

}  // namespace scfloam
