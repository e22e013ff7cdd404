#include "scfloam/registration/scan_to_map.hpp"

#include <ceres/ceres.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <memory>

#include "scfloam/error.hpp"
#include "scfloam/registration/degeneracy.hpp"
#include "scfloam/registration/pose_manifold.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {

FeatureMap::FeatureMap(const RegistrationConfig& registration, const LocalMapConfig& map)
    : edges_(registration.max_neighbor_dist_m, map.edge_spacing_m, map.max_points_per_cell,
             registration.edge_view_tolerance_deg * M_PI / 180.0),
      planes_(registration.max_neighbor_dist_m, map.plane_spacing_m, map.max_points_per_cell) {}

void FeatureMap::insert(const FeatureCloud& edges_lidar, const FeatureCloud& planes_lidar,
                        const Eigen::Isometry3d& T_world_lidar) {
  edges_.insert(edges_lidar, T_world_lidar);
  planes_.insert(planes_lidar, T_world_lidar);
}

void FeatureMap::remove_far(const Eigen::Vector3d& center, double radius_m) {
  edges_.remove_far(center, radius_m);
  planes_.remove_far(center, radius_m);
}

void FeatureMap::clear() {
  edges_.clear();
  planes_.clear();
}

ScanToMapRegistration::ScanToMapRegistration(const RegistrationConfig& config) : config_(config) {
  if (config.knn < 3 || config.knn > VoxelMap::kMaxK)
    throw Error("registration: knn must be in [3, " + std::to_string(VoxelMap::kMaxK) + "]");
  if (config.num_threads > 1) arena_ = std::make_unique<tbb::task_arena>(config.num_threads);
}

namespace {

// Mean and covariance of the k neighbours, eigen-decomposed (ascending eigenvalues).
struct LocalShape {
  Eigen::Vector3d mean;
  Eigen::Vector3d eigenvalues;
  Eigen::Matrix3d eigenvectors;
};

LocalShape local_shape(const VoxelMap::Neighbors& nb) {
  LocalShape s;
  s.mean.setZero();
  for (int i = 0; i < nb.count; ++i) s.mean += nb.points[i].cast<double>();
  s.mean /= nb.count;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int i = 0; i < nb.count; ++i) {
    const Eigen::Vector3d d = nb.points[i].cast<double>() - s.mean;
    cov += d * d.transpose();
  }
  cov /= nb.count;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(cov);
  s.eigenvalues = es.eigenvalues();
  s.eigenvectors = es.eigenvectors();
  return s;
}

// Z-order (Morton) code of p's 1 m cell, 8 bits per axis (wraps beyond +-128 m: it only
// orders the queries, it never decides a match).
std::uint64_t morton_cell(const Eigen::Vector3f& p) {
  auto spread = [](std::uint64_t v) {  // bit i -> bit 3i, for 8 bits
    v &= 0xff;
    v = (v | (v << 8)) & 0x00f00full;
    v = (v | (v << 4)) & 0x0c30c3ull;
    v = (v | (v << 2)) & 0x249249ull;
    return v;
  };
  auto cell = [](float x) { return static_cast<std::uint64_t>(static_cast<int>(std::floor(x)) + 128); };
  return spread(cell(p.x())) | (spread(cell(p.y())) << 1) | (spread(cell(p.z())) << 2);
}

}  // namespace

void ScanToMapRegistration::find_matches(const FeatureCloud& edges, const FeatureCloud& planes,
                                         const FeatureMap& map,
                                         const Eigen::Isometry3d& T_world_lidar,
                                         bool first_round) {
  const Eigen::Isometry3f T = T_world_lidar.cast<float>();
  const int k = config_.knn;
  const float radius = static_cast<float>(config_.max_neighbor_dist_m);
  const float refresh2 = static_cast<float>(config_.match_refresh_m * config_.match_refresh_m);
  if (first_round) {
    edge_all_.resize(edges.size());
    plane_all_.resize(planes.size());
    edge_ok_.assign(edges.size(), 0);
    plane_ok_.assign(planes.size(), 0);
    edge_query_.resize(edges.size());
    plane_query_.resize(planes.size());
    // Visit the queries in Z-order of their position, edges then planes: neighbouring queries
    // then read the same map cells and hash slots, which stay in cache (the search is bound by
    // memory latency, not arithmetic). Results are stored by index, so the order is invisible.
    query_order_.resize(edges.size() + planes.size());
    for (std::size_t i = 0; i < edges.size(); ++i)
      query_order_[i] = (morton_cell(edges[i]) << 32) | i;
    for (std::size_t j = 0; j < planes.size(); ++j)
      query_order_[edges.size() + j] = (std::uint64_t{1} << 60) | (morton_cell(planes[j]) << 32) |
                                       (edges.size() + j);
    std::sort(query_order_.begin(), query_order_.end());
  }

  const std::size_t n_edges = edges.size(), total = edges.size() + planes.size();
  const bool view_filter = config_.edge_view_tolerance_deg > 0 && map.edges().stores_views();
  const Eigen::Vector3f sensor = T.translation();
  auto work = [&](const tbb::blocked_range<std::size_t>& range) {
    VoxelMap::Neighbors nb;
    for (std::size_t r = range.begin(); r != range.end(); ++r) {
      const std::size_t i = query_order_[r] & 0xffffffffu;
      if (i < n_edges) {
        const Eigen::Vector3f q = T * edges[i];
        if (!first_round && (q - edge_query_[i]).squaredNorm() < refresh2) continue;
        edge_query_[i] = q;
        edge_ok_[i] = 0;
        if (view_filter) {
          const VoxelMap::View view = VoxelMap::view_of(sensor, q);
          map.edges().knn(q, k, radius, nb, &view);
        } else {
          map.edges().knn(q, k, radius, nb);
        }
        if (nb.count < k) continue;
        const LocalShape s = local_shape(nb);
        if (!(s.eigenvalues[2] > config_.edge_line_ratio * s.eigenvalues[1])) continue;
        if (config_.edge_max_residual_m > 0) {
          // A point this far from the line it found is not on it: the line is another face
          // of a trunk or pole, or a loose cluster, seen from the viewpoints the map was built
          // from. Under the Huber loss each such match still pulls with full force, towards
          // those viewpoints: on simulated drives the pose lagged behind by up to 0.02 % of
          // the distance (docs/odometry.md, "Session 22").
          const Eigen::Vector3d d = s.eigenvectors.col(2);
          const Eigen::Vector3d v = q.cast<double>() - s.mean;
          if ((v - v.dot(d) * d).squaredNorm() > config_.edge_max_residual_m * config_.edge_max_residual_m)
            continue;
        }
        edge_all_[i] = {edges[i].cast<double>(), s.mean, s.eigenvectors.col(2)};
        edge_ok_[i] = 1;
      } else {
        const std::size_t j = i - n_edges;
        const Eigen::Vector3f q = T * planes[j];
        if (!first_round && (q - plane_query_[j]).squaredNorm() < refresh2) continue;
        plane_query_[j] = q;
        plane_ok_[j] = 0;
        map.planes().knn(q, k, radius, nb);
        if (nb.count < k) continue;
        const LocalShape s = local_shape(nb);
        if (s.eigenvalues[1] < config_.plane_min_spread_ratio * s.eigenvalues[2]) continue;
        const Eigen::Vector3d n = s.eigenvectors.col(0);
        const double offset = -n.dot(s.mean);
        bool flat = true;
        for (int m = 0; m < nb.count && flat; ++m)
          flat = std::abs(n.dot(nb.points[m].cast<double>()) + offset) <= config_.plane_max_dist_m;
        if (!flat) continue;
        plane_all_[j] = {planes[j].cast<double>(), n, offset};
        plane_ok_[j] = 1;
      }
    }
  };
  if (arena_) {
    arena_->execute([&] { tbb::parallel_for(tbb::blocked_range<std::size_t>(0, total, 256), work); });
  } else {
    work(tbb::blocked_range<std::size_t>(0, total));
  }
  edge_out_.clear();
  plane_out_.clear();
  for (std::size_t i = 0; i < edges.size(); ++i)
    if (edge_ok_[i]) edge_out_.push_back(edge_all_[i]);
  for (std::size_t i = 0; i < planes.size(); ++i)
    if (plane_ok_[i]) plane_out_.push_back(plane_all_[i]);
}

std::pair<int, int> ScanToMapRegistration::count_matches(const FeatureCloud& edges,
                                                         const FeatureCloud& planes,
                                                         const FeatureMap& map,
                                                         const Eigen::Isometry3d& T_world_lidar) {
  find_matches(edges, planes, map, T_world_lidar, true);
  return {static_cast<int>(edge_out_.size()), static_cast<int>(plane_out_.size())};
}

namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Basis6 = Eigen::Matrix<double, 6, Eigen::Dynamic>;

// Gauss-Newton Hessians J^T J (tangent [omega; v]) of the matches at T: `plain` unrobustified,
// which measures the geometry alone (how many matches constrain each direction, whatever their
// current residual: far from the solution the loss would hide a good wall), and, when
// huber_delta_m > 0, `robust` with the loss; plus the sum of point-to-line/plane distances.
// Fixed blocks summed in block order: the same sums whatever the threads.
struct Hessians {
  Matrix6 plain = Matrix6::Zero(), robust = Matrix6::Zero();
  double sum_dist = 0, sum_sq = 0;
};

Hessians hessians_of(const std::vector<EdgeMatch>& edges, const std::vector<PlaneMatch>& planes,
                     const Eigen::Isometry3d& T, double huber_delta_m, tbb::task_arena* arena) {
  const Eigen::Matrix3d R = T.linear();
  const Eigen::Vector3d t = T.translation();
  constexpr std::size_t kBlock = 1024;
  const std::size_t n_edges = edges.size(), total = n_edges + planes.size();
  const std::size_t n_blocks = (total + kBlock - 1) / kBlock;
  std::vector<Hessians> blocks(n_blocks);
  auto run_block = [&](std::size_t b) {
    Hessians& h = blocks[b];
    const std::size_t begin = b * kBlock, end = std::min(total, begin + kBlock);
    for (std::size_t i = begin; i < std::min(end, n_edges); ++i) {
      Jacobian36 J;
      Eigen::Vector3d r = edge_residual(edges[i], R, t, &J);
      h.sum_dist += r.norm();
      h.sum_sq += r.squaredNorm();
      h.plain.noalias() += J.transpose() * J;
      if (huber_delta_m > 0) {
        robustify_huber<3>(huber_delta_m, r, &J);
        h.robust.noalias() += J.transpose() * J;
      }
    }
    for (std::size_t i = std::max(begin, n_edges); i < end; ++i) {
      Jacobian16 J;
      Eigen::Matrix<double, 1, 1> r(plane_residual(planes[i - n_edges], R, t, &J));
      h.sum_dist += std::abs(r[0]);
      h.sum_sq += r[0] * r[0];
      h.plain.noalias() += J.transpose() * J;
      if (huber_delta_m > 0) {
        robustify_huber<1>(huber_delta_m, r, &J);
        h.robust.noalias() += J.transpose() * J;
      }
    }
  };
  if (arena && n_blocks > 1)
    arena->execute([&] { tbb::parallel_for(std::size_t{0}, n_blocks, run_block); });
  else
    for (std::size_t b = 0; b < n_blocks; ++b) run_block(b);
  Hessians sum;
  for (const Hessians& h : blocks) {
    sum.plain += h.plain;
    sum.robust += h.robust;
    sum.sum_dist += h.sum_dist;
    sum.sum_sq += h.sum_sq;
  }
  return sum;
}

// Ends a Ceres solve once an accepted step is smaller than `tolerance` (tangent norm, rad and
// m): further iterations of the round would not change the pose at the scale that matters,
// and the next round re-matches anyway. Ceres' own parameter_tolerance is relative to the
// block's norm, i.e. to the distance from the world origin.
class SmallStepStop : public ceres::IterationCallback {
 public:
  explicit SmallStepStop(double tolerance) : tolerance_(tolerance) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    return s.iteration > 0 && s.step_is_successful && s.step_norm < tolerance_
               ? ceres::SOLVER_TERMINATE_SUCCESSFULLY
               : ceres::SOLVER_CONTINUE;
  }

 private:
  double tolerance_;
};

// The prediction as a prior along weak directions: rows sqrt(w) b^T (pose [-] prediction) for
// each column b of `rotations` (weight w_rot) and `translations` (w_tra), [-] being
// PoseManifold::Minus. Its Jacobian is MinusJacobian's (exact at the prediction; a solve moves
// a few centimetres and milliradians from it).
class WeakDirectionPrior : public ceres::CostFunction {
 public:
  WeakDirectionPrior(const double* prediction, const Basis6& rotations, double w_rot,
                     const Basis6& translations, double w_tra)
      : rows_(rotations.cols() + translations.cols(), 6) {
    std::copy(prediction, prediction + 7, prediction_);
    const auto nr = rotations.cols();
    if (nr > 0) rows_.topRows(nr) = std::sqrt(w_rot) * rotations.transpose();
    if (translations.cols() > 0) rows_.bottomRows(translations.cols()) = std::sqrt(w_tra) * translations.transpose();
    set_num_residuals(static_cast<int>(rows_.rows()));
    mutable_parameter_block_sizes()->push_back(7);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    Eigen::Matrix<double, 6, 1> d;
    manifold_.Minus(parameters[0], prediction_, d.data());
    Eigen::Map<Eigen::VectorXd>(residuals, rows_.rows()) = rows_ * d;
    if (jacobians && jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor>> J(jacobians[0], rows_.rows(), 7);
      J.setZero();
      J.leftCols<6>() = rows_;
    }
    return true;
  }

 private:
  double prediction_[7];
  Eigen::Matrix<double, Eigen::Dynamic, 6> rows_;
  PoseManifold manifold_;
};

// How the fallback treats a block's weak directions: with a prior weight of 0 they are frozen
// at the prediction (solution remapping), otherwise the prediction is a prior there. Per
// block: the directions frozen, those the solver may move in, those under the prior.
Degeneracy::Part frozen_part(double prior_weight) {
  return prior_weight > 0 ? Degeneracy::Part::kNone : Degeneracy::Part::kWeak;
}
Degeneracy::Part free_part(double prior_weight) {
  return prior_weight > 0 ? Degeneracy::Part::kAll : Degeneracy::Part::kStrong;
}
Degeneracy::Part prior_part(double prior_weight) {
  return prior_weight > 0 ? Degeneracy::Part::kWeak : Degeneracy::Part::kNone;
}

bool finite_pose(const double* pose) {
  for (int i = 0; i < 7; ++i)
    if (!std::isfinite(pose[i])) return false;
  return true;
}

}  // namespace

RegistrationResult ScanToMapRegistration::align(const FeatureCloud& edges_lidar,
                                                const FeatureCloud& planes_lidar,
                                                const FeatureMap& map,
                                                const Eigen::Isometry3d& T_world_lidar_init,
                                                int rounds) {
  RegistrationResult result;
  double init[7], pose[7];
  pose_to_block(T_world_lidar_init, init);
  std::copy(init, init + 7, pose);
  PoseManifold manifold;
  constexpr std::size_t kMinMatches = 10;  // fewer cannot pin down 6 dof with any margin
  edge_out_.clear();
  plane_out_.clear();

  const double w_rot = config_.degeneracy_prior_rotation_weight;
  const double w_tra = config_.degeneracy_prior_translation_weight;
  const int max_rounds = std::max(rounds, config_.outer_iterations_max);
  for (int round = 0; round < max_rounds; ++round) {
    find_matches(edges_lidar, planes_lidar, map, block_to_pose(pose), round == 0);
    if (edge_out_.size() + plane_out_.size() < kMinMatches) break;
    // Degenerate directions of this round's matches: the solver may not move along them
    // (they would follow noise, and through the nonlinearity disturb the other directions).
    std::unique_ptr<SubspacePoseManifold> subspace;
    std::unique_ptr<WeakDirectionPrior> prior;
    if (config_.degeneracy_fallback) {
      const Degeneracy cond(
          hessians_of(edge_out_, plane_out_, block_to_pose(pose), 0.0, arena_.get()).plain, config_);
      if (cond.weak() == 6) break;  // nothing is constrained: keep the guess
      if (cond.weak() > 0) {
        using Part = Degeneracy::Part;
        if (cond.directions(frozen_part(w_rot), frozen_part(w_tra)).cols() > 0)
          subspace = std::make_unique<SubspacePoseManifold>(
              cond.directions(free_part(w_rot), free_part(w_tra)));
        const Basis6 soft_rot = cond.directions(prior_part(w_rot), Part::kNone);
        const Basis6 soft_tra = cond.directions(Part::kNone, prior_part(w_tra));
        if (soft_rot.cols() + soft_tra.cols() > 0)
          prior = std::make_unique<WeakDirectionPrior>(init, soft_rot, w_rot, soft_tra, w_tra);
      }
    }
    NormalEquationCost cost(edge_out_, plane_out_, config_.huber_delta_m, arena_.get());
    ceres::Problem::Options problem_options;
    problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    problem.AddParameterBlock(pose, 7, subspace ? static_cast<ceres::Manifold*>(subspace.get())
                                                : &manifold);
    problem.AddResidualBlock(&cost, nullptr, pose);
    if (prior) problem.AddResidualBlock(prior.get(), nullptr, pose);
    ceres::Solver::Options options;
    // 6 unknowns: the normal equations are a 6x6 Cholesky; QR of the ~10^4 x 6 Jacobian cost
    // more and gains no accuracy that matters on a problem this well scaled.
    options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
    SmallStepStop small_step(config_.solver_step_tolerance);
    if (config_.solver_step_tolerance > 0) options.callbacks.push_back(&small_step);
    options.max_num_iterations = config_.inner_iterations;
    options.minimizer_progress_to_stdout = false;
    options.logging_type = ceres::SILENT;
    options.num_threads = 1;
    ceres::Solver::Summary summary;
    const Eigen::Isometry3d T_before = block_to_pose(pose);
    double before[7];
    std::copy(pose, pose + 7, before);
    ceres::Solve(options, &problem, &summary);
    if (!finite_pose(pose)) {  // never hand a NaN pose on: keep the last good one
      std::copy(before, before + 7, pose);
      break;
    }
    ++result.rounds;
    const Eigen::Isometry3d step = T_before.inverse() * block_to_pose(pose);
    const double step_m = step.translation().norm();
    const double step_deg = rotation_angle_rad(step.linear()) * 180.0 / M_PI;
    if (step_m < config_.converged_translation_m && step_deg < config_.converged_rotation_deg)
      break;
    // The frame's rounds are spent: go on only while the pose is still moving.
    if (round + 1 >= rounds && step_m < config_.unconverged_translation_m &&
        step_deg < config_.unconverged_rotation_deg)
      break;
  }

  // Hessians and residuals of the final matches at the solution.
  const std::size_t n = edge_out_.size() + plane_out_.size();
  const Hessians final_h = n < kMinMatches ? Hessians{}
                                           : hessians_of(edge_out_, plane_out_, block_to_pose(pose),
                                                         config_.huber_delta_m, arena_.get());
  const double sum_dist = final_h.sum_dist;
  result.hessian = config_.huber_delta_m > 0 ? final_h.robust : final_h.plain;
  const Degeneracy cond(final_h.plain, config_);
  // Solution remapping of the frozen directions: whatever the rounds did along the final weak
  // ones is undone, so the pose there is the initial guess (the motion model). Where the
  // prediction was a prior instead, the solve has already weighed it.
  if (config_.degeneracy_fallback && cond.weak() > 0) {
    const Basis6 W = cond.directions(frozen_part(w_rot), frozen_part(w_tra));
    if (W.cols() > 0) {
      Eigen::Matrix<double, 6, 1> delta;
      manifold.Minus(pose, init, delta.data());
      delta -= W * (W.transpose() * delta);
      manifold.Plus(init, delta.data(), pose);
    }
    result.fallback_applied = true;
  }
  result.T_world_lidar = block_to_pose(pose);
  result.edge_matches = static_cast<int>(edge_out_.size());
  result.plane_matches = static_cast<int>(plane_out_.size());
  result.mean_residual_m = n ? sum_dist / n : 0;
  // A point-to-line residual is a 3-vector across the line (2 dof), a point-to-plane one 1 dof.
  const double dof = 2.0 * static_cast<double>(edge_out_.size()) +
                     static_cast<double>(plane_out_.size()) - 6.0;
  result.residual_variance_m2 = dof > 0 ? final_h.sum_sq / dof : 0;
  result.rotation_eigenvalues = cond.rot_values;
  result.translation_eigenvalues = cond.tra_values;
  result.weakest_translation_dir = cond.tra_vectors.col(0);
  result.weak_rotation_dirs = cond.weak_rot;
  result.weak_translation_dirs = cond.weak_tra;
  result.degenerate = n < kMinMatches || cond.weak() > 0;
  return result;
}

RegistrationResult register_features(const FeatureCloud& edges_lidar,
                                     const FeatureCloud& planes_lidar, const FeatureMap& map,
                                     const Eigen::Isometry3d& T_world_lidar_init,
                                     const RegistrationConfig& config, int rounds) {
  ScanToMapRegistration reg(config);
  return reg.align(edges_lidar, planes_lidar, map, T_world_lidar_init, rounds);
}

}  // namespace scfloam
