#include "scfloam/loop/loop_registration.hpp"

#include <cmath>
#include <cstdio>

#include "scfloam/se3.hpp"

namespace scfloam {
namespace {

// Coarse stage: correspondences within a wider radius, on a map thinned by the same factor,
// so that a cell holds about as many points as a fine one and queries cost about the same.
RegistrationConfig coarse_registration(const LoopRegistrationConfig& config,
                                       const RegistrationConfig& registration) {
  RegistrationConfig coarse = registration;
  coarse.max_neighbor_dist_m = std::max(config.coarse_radius_m, registration.max_neighbor_dist_m);
  return coarse;
}

LocalMapConfig coarse_map_config(const LoopRegistrationConfig& config,
                                 const RegistrationConfig& registration,
                                 const LocalMapConfig& map_config) {
  const double widening =
      coarse_registration(config, registration).max_neighbor_dist_m / registration.max_neighbor_dist_m;
  LocalMapConfig coarse = map_config;
  coarse.edge_spacing_m *= widening;
  coarse.plane_spacing_m *= widening;
  return coarse;
}

}  // namespace

std::vector<Eigen::Isometry3d> loop_initial_guesses(const Eigen::Isometry3d& T_world_loop,
                                                    const Eigen::Isometry3d& T_world_current,
                                                    double sc_yaw_rad) {
  std::vector<Eigen::Isometry3d> guesses;
  // 1. What the poses say: right when drift since the loop keyframe is small.
  guesses.push_back(T_world_loop.inverse() * T_world_current);
  // 2. What Scan Context says: the same place, turned by its yaw (quantised to a sector).
  //    Right when drift is large, as the gate allows after a long drive.
  Eigen::Isometry3d sc = Eigen::Isometry3d::Identity();
  sc.linear() = so3_exp(Eigen::Vector3d(0, 0, sc_yaw_rad));
  guesses.push_back(sc);
  return guesses;
}

LoopSubmap::LoopSubmap(const std::vector<KeyframeView>& keyframes, std::size_t anchor,
                       std::size_t first_keyframe, const LoopRegistrationConfig& config,
                       const RegistrationConfig& registration, const LocalMapConfig& map_config)
    : first_(first_keyframe),
      last_(first_keyframe + keyframes.size() - 1),
      anchor_(first_keyframe + anchor),
      coarse_(coarse_registration(config, registration),
              coarse_map_config(config, registration, map_config)),
      fine_(registration, map_config) {
  const Eigen::Isometry3d T_anchor_world = keyframes.at(anchor).T_world_lidar.inverse();
  static const FeatureCloud kEmpty;
  for (const auto& kf : keyframes) {
    const Eigen::Isometry3d T_anchor_kf = T_anchor_world * kf.T_world_lidar;
    const FeatureCloud& edges = kf.edges ? *kf.edges : kEmpty;
    const FeatureCloud& planes = kf.planes ? *kf.planes : kEmpty;
    coarse_.insert(edges, planes, T_anchor_kf);
    fine_.insert(edges, planes, T_anchor_kf);
  }
}

LoopMatch register_loop_features(const KeyframeView& current, const LoopSubmap& submap,
                                 const Eigen::Isometry3d& T_world_anchor,
                                 const Eigen::Isometry3d& T_world_loop, double sc_yaw_rad,
                                 const LoopRegistrationConfig& config,
                                 const RegistrationConfig& registration) {
  LoopMatch best;
  best.reason = "no features";
  if (!current.edges || !current.planes) return best;
  const std::size_t features = current.edges->size() + current.planes->size();
  if (features == 0) return best;

  // The submap lives in its anchor keyframe's frame: guesses go in, results come out, through
  // the anchor's relative pose to the loop keyframe under the current estimates.
  const Eigen::Isometry3d T_anchor_loop = T_world_anchor.inverse() * T_world_loop;
  ScanToMapRegistration coarse_solver(coarse_registration(config, registration));
  ScanToMapRegistration fine_solver(registration);
  for (const Eigen::Isometry3d& T_loop_guess :
       loop_initial_guesses(T_world_loop, current.T_world_lidar, sc_yaw_rad)) {
    const RegistrationResult rough = coarse_solver.align(
        *current.edges, *current.planes, submap.coarse(), T_anchor_loop * T_loop_guess,
        config.coarse_rounds);
    const RegistrationResult r = fine_solver.align(*current.edges, *current.planes, submap.fine(),
                                                   rough.T_world_lidar, config.rounds);
    LoopMatch match;
    match.T_loop_current = T_anchor_loop.inverse() * r.T_world_lidar;
    match.inlier_fraction = static_cast<double>(r.edge_matches + r.plane_matches) / features;
    match.residual_m = r.mean_residual_m;
    match.accepted = match.inlier_fraction >= config.min_inlier_fraction &&
                     match.residual_m <= config.max_mean_residual_m;
    if (!match.accepted) {
      char buf[128];
      std::snprintf(buf, sizeof buf, "inliers %.2f (min %.2f), residual %.3f m (max %.3f)",
                    match.inlier_fraction, config.min_inlier_fraction, match.residual_m,
                    config.max_mean_residual_m);
      match.reason = buf;
    }
    if (match.accepted) return match;
    if (best.reason == "no features" || match.inlier_fraction > best.inlier_fraction) best = match;
  }
  return best;
}

LoopMatch register_loop_features(const KeyframeView& current,
                                 const std::vector<KeyframeView>& submap, std::size_t loop_index,
                                 double sc_yaw_rad, const LoopRegistrationConfig& config,
                                 const RegistrationConfig& registration,
                                 const LocalMapConfig& map_config) {
  if (loop_index >= submap.size()) {
    LoopMatch none;
    none.reason = "no submap";
    return none;
  }
  const LoopSubmap map(submap, loop_index, 0, config, registration, map_config);
  const Eigen::Isometry3d& T_world_loop = submap[loop_index].T_world_lidar;
  return register_loop_features(current, map, T_world_loop, T_world_loop, sc_yaw_rad, config,
                                registration);
}

}  // namespace scfloam
