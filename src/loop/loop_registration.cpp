#include "scfloam/loop/loop_registration.hpp"

#include <cmath>

#include "scfloam/registration/scan_to_map.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {

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

LoopMatch register_loop_features(const KeyframeView& current,
                                 const std::vector<KeyframeView>& submap, std::size_t loop_index,
                                 double sc_yaw_rad, const LoopRegistrationConfig& config,
                                 const RegistrationConfig& registration,
                                 const LocalMapConfig& map_config) {
  LoopMatch best;
  best.reason = "no features";
  if (!current.edges || !current.planes || loop_index >= submap.size()) return best;
  const std::size_t features = current.edges->size() + current.planes->size();
  if (features == 0) return best;

  // The submap lives in the loop keyframe's frame, so the result is T_loop_current directly.
  const Eigen::Isometry3d T_loop_world = submap[loop_index].T_world_lidar.inverse();
  // Coarse: correspondences within a wider radius, on a map thinned by the same factor, so
  // that a cell holds about as many points as a fine one and queries cost about the same.
  RegistrationConfig coarse = registration;
  coarse.max_neighbor_dist_m = std::max(config.coarse_radius_m, registration.max_neighbor_dist_m);
  const double widening = coarse.max_neighbor_dist_m / registration.max_neighbor_dist_m;
  LocalMapConfig coarse_map_config = map_config;
  coarse_map_config.edge_spacing_m *= widening;
  coarse_map_config.plane_spacing_m *= widening;
  FeatureMap coarse_map(coarse, coarse_map_config), fine_map(registration, map_config);
  static const FeatureCloud kEmpty;
  for (const auto& kf : submap) {
    const Eigen::Isometry3d T_loop_kf = T_loop_world * kf.T_world_lidar;
    coarse_map.insert(kf.edges ? *kf.edges : kEmpty, kf.planes ? *kf.planes : kEmpty, T_loop_kf);
    fine_map.insert(kf.edges ? *kf.edges : kEmpty, kf.planes ? *kf.planes : kEmpty, T_loop_kf);
  }

  ScanToMapRegistration coarse_solver(coarse), fine_solver(registration);
  for (const Eigen::Isometry3d& guess :
       loop_initial_guesses(submap[loop_index].T_world_lidar, current.T_world_lidar, sc_yaw_rad)) {
    const RegistrationResult rough =
        coarse_solver.align(*current.edges, *current.planes, coarse_map, guess, config.coarse_rounds);
    const RegistrationResult r = fine_solver.align(*current.edges, *current.planes, fine_map,
                                                   rough.T_world_lidar, config.rounds);
    LoopMatch match;
    match.T_loop_current = r.T_world_lidar;
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

}  // namespace scfloam
