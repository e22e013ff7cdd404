// Scan Context (Kim & Kim 2018): a polar rings x sectors image of a scan, each bin holding the
// maximum point height above the ground, plus the keys used to search and align it.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "scfloam/loop/config.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

struct ScanContext {
  Eigen::MatrixXf bins;          // num_rings x num_sectors; max height (m) above ground, 0 = empty
  Eigen::VectorXf ring_key;      // num_rings: mean of each ring (occupancy weighted by height)
  Eigen::VectorXf sector_key;    // num_sectors: mean of each sector column
  Eigen::VectorXf column_norms;  // num_sectors: L2 norm of each column, 0 for an empty column

  bool empty() const { return column_norms.size() == 0 || column_norms.maxCoeff() <= 0.0f; }
};

// Accumulates points (lidar frame, z up) into the grid; several clouds may be added, e.g. the
// edge and the plane feature clouds of one keyframe. Sector 0 starts at azimuth 0 (+x) and
// sectors grow counter-clockwise (towards +y). A non-zero `lateral_offset_m` centres the grid
// at (0, lateral_offset_m): a virtual sensor one lane to the side (Scan Context++'s lateral
// augmentation), for revisits driven in another lane.
class ScanContextBuilder {
 public:
  explicit ScanContextBuilder(const ScanContextConfig& config, float lateral_offset_m = 0.0f);
  void add(const std::vector<Eigen::Vector3f>& points_lidar);
  void add(const std::vector<LidarPoint>& points_lidar);
  ScanContext finish() const;  // computes the keys; the builder can keep accumulating

 private:
  void add_point(float x, float y, float z);
  ScanContextConfig config_;
  float lateral_offset_m_;
  float ring_width_m_, sector_width_rad_, max_radius_sq_;
  Eigen::MatrixXf bins_;
};

ScanContext make_scan_context(const std::vector<Eigen::Vector3f>& points_lidar,
                              const ScanContextConfig& config);
ScanContext make_scan_context(const std::vector<LidarPoint>& points_lidar,
                              const ScanContextConfig& config);
// The paper's descriptor: the union of a keyframe's edge and plane feature clouds.
ScanContext make_scan_context(const std::vector<Eigen::Vector3f>& edges_lidar,
                              const std::vector<Eigen::Vector3f>& planes_lidar,
                              const ScanContextConfig& config);

// Best column shift between two descriptors. Convention: loop column j corresponds to current
// column (j + shift_sectors) mod num_sectors, and yaw_loop_current_rad is the yaw of the
// rotation T_loop_current: p_loop ~= Rz(yaw_loop_current_rad) * p_current, in (-pi, pi].
struct ColumnAlignment {
  int shift_sectors = 0;
  double distance = 1.0;  // mean cosine distance of column pairs that are both non-empty, [0, 1]
  double yaw_loop_current_rad = 0.0;
};

// Mean cosine distance for one shift (1 when no column pair is non-empty in both).
double column_distance(const ScanContext& current, const ScanContext& loop, int shift_sectors);

// Coarse shift from the sector keys, then the best column distance within
// +- round(fine_search_ratio * num_sectors) sectors around it.
ColumnAlignment align_scan_contexts(const ScanContext& current, const ScanContext& loop,
                                    double fine_search_ratio);

// Yaw of T_loop_current for a column shift (see ColumnAlignment), wrapped to (-pi, pi].
double shift_to_yaw_rad(int shift_sectors, int num_sectors);

}  // namespace scfloam
