#include "scfloam/loop/loop_registration.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <optional>

#include "scfloam/se3.hpp"

namespace scfloam {
namespace {

// Coarse stage: correspondences within a wider radius, on a map thinned by the same factor,
// so that a cell holds about as many points as a fine one and queries cost about the same.
RegistrationConfig coarse_registration(const LoopRegistrationConfig& config,
                                       const RegistrationConfig& registration) {
  RegistrationConfig coarse = registration;
  coarse.max_neighbor_dist_m = std::max(config.coarse_radius_m, registration.max_neighbor_dist_m);
  coarse.edge_max_residual_m = 0;  // the start may be metres off: every line within reach counts
  return coarse;
}

// Keyframes of a loop are seen from other directions than the current one (and the submap is
// stored in its anchor's frame): no viewing-direction filter.
RegistrationConfig without_view_filter(RegistrationConfig registration) {
  registration.edge_view_tolerance_deg = 0;
  return registration;
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
      coarse_registration_(coarse_registration(config, without_view_filter(registration))),
      coarse_map_(coarse_map_config(config, registration, map_config)),
      fine_(without_view_filter(registration), map_config) {
  const Eigen::Isometry3d T_anchor_world = keyframes.at(anchor).T_world_lidar.inverse();
  const auto append = [](const FeatureCloud* cloud, const Eigen::Isometry3f& T, FeatureCloud& out) {
    if (cloud == nullptr) return;
    for (const Eigen::Vector3f& p : *cloud) out.push_back(T * p);
  };
  std::size_t edges = 0, planes = 0;
  for (const auto& kf : keyframes) {
    edges += kf.edges ? kf.edges->size() : 0;
    planes += kf.planes ? kf.planes->size() : 0;
  }
  edges_anchor_.reserve(edges);
  planes_anchor_.reserve(planes);
  for (const auto& kf : keyframes) {
    const Eigen::Isometry3f T_anchor_kf = (T_anchor_world * kf.T_world_lidar).cast<float>();
    append(kf.edges, T_anchor_kf, edges_anchor_);
    append(kf.planes, T_anchor_kf, planes_anchor_);
  }
  fine_.insert(edges_anchor_, planes_anchor_, Eigen::Isometry3d::Identity());
}

const FeatureMap& LoopSubmap::coarse() const {
  if (!coarse_) {
    coarse_.emplace(coarse_registration_, coarse_map_);
    coarse_->insert(edges_anchor_, planes_anchor_, Eigen::Isometry3d::Identity());
  }
  return *coarse_;
}

Eigen::Matrix<double, 6, 6> loop_edge_information(const RegistrationResult& r,
                                                  const Eigen::Isometry3d& T_anchor_loop,
                                                  double inflation) {
  using Matrix6 = Eigen::Matrix<double, 6, 6>;
  if (!(inflation > 0) || !(r.residual_variance_m2 > 0)) return Matrix6::Zero();
  // The registration moves T_anchor_current = (R, t) to (Exp(w) R, t + v): a left perturbation
  // of T_anchor_current by the twist [w; v + t x w] (rotation first), i.e. M [w; v].
  Matrix6 M = Matrix6::Identity();
  M.block<3, 3>(3, 0) = skew(r.T_world_lidar.translation());
  // In the loop keyframe's frame that twist is Ad(T_loop_anchor) of it, and the edge residual
  // of E = T_loop_current T_current_loop' (~ identity at the solution) moves by the same twist.
  const Eigen::Isometry3d T_loop_anchor = T_anchor_loop.inverse();
  const Eigen::Matrix3d R = T_loop_anchor.linear();
  Matrix6 Ad = Matrix6::Zero();
  Ad.block<3, 3>(0, 0) = R;
  Ad.block<3, 3>(3, 3) = R;
  Ad.block<3, 3>(3, 0) = skew(T_loop_anchor.translation()) * R;
  const Matrix6 N = Ad * M;  // residual = N * delta
  const Matrix6 N_inv = N.inverse();
  Matrix6 info = N_inv.transpose() * (r.hessian / (r.residual_variance_m2 * inflation)) * N_inv;
  info = 0.5 * (info + info.transpose());
  // The pose graph needs a Cholesky factor: a direction the match leaves free (eigenvalue ~0)
  // has no information to give, and the edge falls back to the fixed sigmas.
  if (!info.allFinite()) return Matrix6::Zero();
  const Eigen::SelfAdjointEigenSolver<Matrix6> eig(info, Eigen::EigenvaluesOnly);
  if (eig.info() != Eigen::Success || !(eig.eigenvalues()[0] > 1e-12 * eig.eigenvalues()[5]))
    return Matrix6::Zero();
  return info;
}

LoopMatch register_loop_features(const KeyframeView& current, const LoopSubmap& submap,
                                 const Eigen::Isometry3d& T_world_anchor,
                                 const Eigen::Isometry3d& T_world_loop, double sc_yaw_rad,
                                 const LoopRegistrationConfig& config,
                                 const RegistrationConfig& odometry_registration) {
  RegistrationConfig registration = without_view_filter(odometry_registration);
  registration.knn = config.knn;
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
  // Counts the check's matches at the solved pose when its tests differ from the solve's
  // (otherwise the solve's own counts are the check's). The check counts F-LOAM's matches
  // (0.2 m flatness, no residual cut for edges): its thresholds were measured with
  // those, whatever stricter tests the solve uses.
  std::optional<ScanToMapRegistration> check_solver;
  if (config.check_plane_max_dist_m != registration.plane_max_dist_m || registration.edge_max_residual_m != 0) {
    RegistrationConfig check_registration = registration;
    check_registration.plane_max_dist_m = config.check_plane_max_dist_m;
    check_registration.edge_max_residual_m = 0;
    check_solver.emplace(check_registration);
  }
  const std::vector<Eigen::Isometry3d> guesses =
      loop_initial_guesses(T_world_loop, current.T_world_lidar, sc_yaw_rad);
  // Attempt 0 (fine_first): the fine stage alone from the pose guess; then coarse to fine from
  // each guess.
  for (std::size_t attempt = config.fine_first ? 0 : 1; attempt <= guesses.size(); ++attempt) {
    const bool fine_only = attempt == 0;
    const Eigen::Isometry3d start = T_anchor_loop * guesses[fine_only ? 0 : attempt - 1];
    const Eigen::Isometry3d fine_start =
        fine_only ? start
                  : coarse_solver
                        .align(*current.edges, *current.planes, submap.coarse(), start,
                               config.coarse_rounds)
                        .T_world_lidar;
    const RegistrationResult r = fine_solver.align(*current.edges, *current.planes, submap.fine(),
                                                   fine_start, config.rounds);
    LoopMatch match;
    match.T_loop_current = T_anchor_loop.inverse() * r.T_world_lidar;
    if (config.information_inflation > 0)
      match.information = loop_edge_information(r, T_anchor_loop, config.information_inflation);
    int inliers = r.edge_matches + r.plane_matches;
    if (check_solver) {
      const auto [edges, planes] =
          check_solver->count_matches(*current.edges, *current.planes, submap.fine(), r.T_world_lidar);
      inliers = edges + planes;
    }
    match.inlier_fraction = static_cast<double>(inliers) / features;
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
