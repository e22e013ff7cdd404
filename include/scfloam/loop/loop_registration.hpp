// Loop registration: the relative pose between a revisiting keyframe and the place it
// revisits. The paper's method registers the current keyframe's edge and plane features to a
// feature submap of the loop keyframe and its neighbours, with the odometry's own solver; the
// baseline (Simple-SC-F-LOAM, SC-A-LOAM) runs point-to-point ICP between downsampled raw clouds.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "scfloam/config.hpp"
#include "scfloam/loop/loop_registration_config.hpp"
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
};

// Initial guesses tried in order: the current poses' relative transform, then the place
// hypothesis of Scan Context (same position, rotated by its yaw) when the first fails.
std::vector<Eigen::Isometry3d> loop_initial_guesses(const Eigen::Isometry3d& T_world_loop,
                                                    const Eigen::Isometry3d& T_world_current,
                                                    double sc_yaw_rad);

// The paper's method. `submap` holds the loop keyframe and its neighbours; `loop_index` says
// which of them is the loop keyframe.
LoopMatch register_loop_features(const KeyframeView& current, const std::vector<KeyframeView>& submap,
                                 std::size_t loop_index, double sc_yaw_rad,
                                 const LoopRegistrationConfig& config,
                                 const RegistrationConfig& registration,
                                 const LocalMapConfig& map_config);

// The baseline: ICP of the current raw cloud to the submap's raw clouds.
LoopMatch register_loop_icp(const KeyframeView& current, const std::vector<KeyframeView>& submap,
                            std::size_t loop_index, double sc_yaw_rad,
                            const LoopRegistrationConfig& config);

}  // namespace scfloam
