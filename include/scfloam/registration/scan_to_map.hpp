// Feature-to-map registration: edges to lines, planes to planes, solved on Ceres with the
// correspondences refreshed between solver rounds. Used by the odometry (frame to local map)
// and by loop registration (keyframe to submap); depends on nothing but core and Ceres.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "scfloam/config.hpp"
#include "scfloam/registration/feature_costs.hpp"
#include "scfloam/registration/voxel_map.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

// Edge and plane points in world coordinates.
class FeatureMap {
 public:
  FeatureMap(const RegistrationConfig& registration, const LocalMapConfig& map);

  // Adds a frame's features placed at T_world_lidar.
  void insert(const FeatureCloud& edges_lidar, const FeatureCloud& planes_lidar,
              const Eigen::Isometry3d& T_world_lidar);
  void remove_far(const Eigen::Vector3d& center, double radius_m);
  void clear();

  const VoxelMap& edges() const { return edges_; }
  const VoxelMap& planes() const { return planes_; }

 private:
  VoxelMap edges_, planes_;
};

struct RegistrationResult {
  Eigen::Isometry3d T_world_lidar = Eigen::Isometry3d::Identity();
  int edge_matches = 0;   // accepted correspondences of the final round
  int plane_matches = 0;
  double mean_residual_m = 0;  // mean point-to-line/plane distance of those, before the loss
  // Variance of one residual component of those (sum of squares over the degrees of freedom):
  // with `hessian`, the solution's covariance is about residual_variance_m2 * hessian^-1.
  double residual_variance_m2 = 0;
  int rounds = 0;              // correspondence rounds actually run
  // Gauss-Newton Hessian J^T J of the final round at the solution, tangent [omega; v].
  Eigen::Matrix<double, 6, 6> hessian = Eigen::Matrix<double, 6, 6>::Zero();
  // Eigenvalues of the rotation and translation blocks of the unrobustified J^T J (the
  // geometry of the matches: ~ number of matches constraining each direction), which decide
  // the weak directions.
  Eigen::Vector3d rotation_eigenvalues = Eigen::Vector3d::Zero();     // ascending
  Eigen::Vector3d translation_eigenvalues = Eigen::Vector3d::Zero();  // ascending
  Eigen::Vector3d weakest_translation_dir = Eigen::Vector3d::Zero();  // world frame, unit
  bool degenerate = false;  // some eigenvalue of either block below its degeneracy threshold
  // Weak directions of the final round (eigenvalue below the threshold), and whether the
  // solve kept the initial guess along them (RegistrationConfig::degeneracy_fallback).
  int weak_rotation_dirs = 0;
  int weak_translation_dirs = 0;
  bool fallback_applied = false;
};

// Keeps its buffers between calls; one instance per thread.
class ScanToMapRegistration {
 public:
  explicit ScanToMapRegistration(const RegistrationConfig& config);

  RegistrationResult align(const FeatureCloud& edges_lidar, const FeatureCloud& planes_lidar,
                           const FeatureMap& map, const Eigen::Isometry3d& T_world_lidar_init,
                           int rounds);

  // The correspondences a round would start from at T_world_lidar, without solving: e.g. to
  // check a solved pose under another match test. {edge matches, plane matches}.
  std::pair<int, int> count_matches(const FeatureCloud& edges_lidar, const FeatureCloud& planes_lidar,
                                    const FeatureMap& map, const Eigen::Isometry3d& T_world_lidar);

  // Correspondences of the last round (for tests and diagnostics).
  const std::vector<EdgeMatch>& edge_matches() const { return edge_out_; }
  const std::vector<PlaneMatch>& plane_matches() const { return plane_out_; }

 private:
  void find_matches(const FeatureCloud& edges, const FeatureCloud& planes, const FeatureMap& map,
                    const Eigen::Isometry3d& T_world_lidar, bool first_round);

  RegistrationConfig config_;
  std::unique_ptr<tbb::task_arena> arena_;  // num_threads > 1: search and cost evaluation
  std::vector<EdgeMatch> edge_all_, edge_out_;
  std::vector<PlaneMatch> plane_all_, plane_out_;
  std::vector<char> edge_ok_, plane_ok_;
  std::vector<Eigen::Vector3f> edge_query_, plane_query_;  // world position at the last search
  std::vector<std::uint64_t> query_order_;  // (Z-order cell << 32) | query index, sorted
};

// One-off convenience: `rounds` correspondence rounds from T_world_lidar_init.
RegistrationResult register_features(const FeatureCloud& edges_lidar,
                                     const FeatureCloud& planes_lidar, const FeatureMap& map,
                                     const Eigen::Isometry3d& T_world_lidar_init,
                                     const RegistrationConfig& config, int rounds);

}  // namespace scfloam
