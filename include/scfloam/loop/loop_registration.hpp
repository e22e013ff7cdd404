// Loop registration: the relative pose between a revisiting keyframe and the place it
// revisits. The paper's method registers the current keyframe's edge and plane features to a
// feature submap of the loop keyframe and its neighbours, with the odometry's own solver; the
// baseline (Simple-SC-F-LOAM, SC-A-LOAM) runs point-to-point ICP between downsampled raw clouds.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "scfloam/config.hpp"
#include "scfloam/loop/loop_registration_config.hpp"
#include "scfloam/registration/scan_to_map.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

// One keyframe as loop registration sees it: its pose now (optimized) and its clouds.
struct KeyframeView {
  Eigen::Isometry3d T_world_lidar = Eigen::Isometry3d::Identity();
  const FeatureCloud* edges = nullptr;   // lidar frame
  const FeatureCloud* planes = nullptr;  // lidar frame
  const FeatureCloud* raw = nullptr;     // downsampled raw scan, lidar frame (ICP baseline)
};

struct LoopMatch {
  bool accepted = false;
  Eigen::Isometry3d T_loop_current = Eigen::Isometry3d::Identity();  // the measured loop edge
  double inlier_fraction = 0;  // features matched (or, for ICP, points within 1 m)
  double residual_m = 0;       // mean point-to-line/plane distance (ICP: RMS distance)
  std::string reason;          // why it was rejected, for the log
  // Information (inverse covariance) of the pose-graph residual of the loop edge current ->
  // loop keyframe (measurement T_loop_current^-1), from the fine match's Hessian and residual
  // variance (loop_edge_information). Zero when the match gives none (ICP, a degenerate
  // match, loop_registration.information_inflation 0): the edge then takes the fixed sigmas.
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
};

// The information of a loop edge's residual [Log R_E; t_E] from a registration of the current
// keyframe in its submap's anchor frame: r.hessian / (r.residual_variance_m2 * inflation),
// carried from the registration's tangent at T_anchor_current to the edge's residual through
// T_anchor_loop. Zero if that is not positive definite.
Eigen::Matrix<double, 6, 6> loop_edge_information(const RegistrationResult& r,
                                                  const Eigen::Isometry3d& T_anchor_loop,
                                                  double inflation);

// Initial guesses tried in order: the current poses' relative transform, then the place
// hypothesis of Scan Context (same position, rotated by its yaw) when the first fails.
std::vector<Eigen::Isometry3d> loop_initial_guesses(const Eigen::Isometry3d& T_world_loop,
                                                    const Eigen::Isometry3d& T_world_current,
                                                    double sc_yaw_rad);

// The feature maps of a submap (coarse and fine), in the frame of its anchor keyframe. Building
// it costs more than registering to it (about 127 vs 38 ms for 51 keyframes), and consecutive
// loop frames revisit neighbouring keyframes, so the loop stage keeps one and reuses it. The
// coarse map is built on first use only (fine_first: a loop whose guess is already good never
// needs it); one thread at a time.
class LoopSubmap {
 public:
  // `keyframes` are keyframes first_keyframe, first_keyframe + 1, ...; `anchor` indexes them.
  LoopSubmap(const std::vector<KeyframeView>& keyframes, std::size_t anchor,
             std::size_t first_keyframe, const LoopRegistrationConfig& config,
             const RegistrationConfig& registration, const LocalMapConfig& map_config);
  std::size_t first_keyframe() const { return first_; }
  std::size_t last_keyframe() const { return last_; }
  std::size_t anchor_keyframe() const { return anchor_; }
  const FeatureMap& coarse() const;
  const FeatureMap& fine() const { return fine_; }

 private:
  std::size_t first_, last_, anchor_;
  RegistrationConfig coarse_registration_;
  LocalMapConfig coarse_map_;
  FeatureCloud edges_anchor_, planes_anchor_;  // every keyframe's features, anchor frame
  mutable std::optional<FeatureMap> coarse_;
  FeatureMap fine_;
};

// The paper's method on a prepared submap: `T_world_anchor` and `T_world_loop` are the current
// estimates of the submap's anchor keyframe and of the loop keyframe (often the same one).
LoopMatch register_loop_features(const KeyframeView& current, const LoopSubmap& submap,
                                 const Eigen::Isometry3d& T_world_anchor,
                                 const Eigen::Isometry3d& T_world_loop, double sc_yaw_rad,
                                 const LoopRegistrationConfig& config,
                                 const RegistrationConfig& registration);

// The paper's method, building the submap: `submap` holds the loop keyframe and its
// neighbours; `loop_index` says which of them is the loop keyframe.
LoopMatch register_loop_features(const KeyframeView& current, const std::vector<KeyframeView>& submap,
                                 std::size_t loop_index, double sc_yaw_rad,
                                 const LoopRegistrationConfig& config,
                                 const RegistrationConfig& registration,
                                 const LocalMapConfig& map_config);

// The baseline: ICP of the current raw cloud to the submap's raw clouds.
LoopMatch register_loop_icp(const KeyframeView& current, const std::vector<KeyframeView>& submap,
                            std::size_t loop_index, double sc_yaw_rad,
                            const LoopRegistrationConfig& config);

// Open3D's ICP gathers its correspondences on OpenMP threads in the order they finish, so its
// result varies in the last bits from run to run, and so do the loops and poses that follow.
// While an object of this class lives, ICP called from the thread that made it runs on one
// OpenMP thread and repeats itself exactly (the pipeline's deterministic mode). OpenMP keeps
// the thread count per thread: other threads, and the threaded mode, are unaffected.
class IcpOnThisThreadRepeatable {
 public:
  IcpOnThisThreadRepeatable();
  ~IcpOnThisThreadRepeatable();
  IcpOnThisThreadRepeatable(const IcpOnThisThreadRepeatable&) = delete;
  IcpOnThisThreadRepeatable& operator=(const IcpOnThisThreadRepeatable&) = delete;

 private:
  void (*set_threads_)(int) = nullptr;
  int previous_threads_ = 0;
};

}  // namespace scfloam
