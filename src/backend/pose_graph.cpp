#include "scfloam/backend/pose_graph.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <limits>

#include <cstdio>

#include "backend/pose_graph_costs.hpp"
#include "scfloam/backend/loop_support.hpp"
#include "scfloam/atomic_file.hpp"
#include "scfloam/error.hpp"
#include "scfloam/se3.hpp"
#include "scfloam/stats.hpp"

namespace scfloam {
using namespace pose_graph_detail;

Eigen::Matrix<double, 6, 6> sqrt_information_from_sigmas(double rotation_sigma_rad,
                                                         double translation_sigma_m) {
  Matrix6d m = Matrix6d::Zero();
  m.diagonal().head<3>().setConstant(1.0 / rotation_sigma_rad);
  m.diagonal().tail<3>().setConstant(1.0 / translation_sigma_m);
  return m;
}

std::size_t PoseGraph::add_node(const Eigen::Isometry3d& T_world_node) {
  const Eigen::Quaterniond q = Eigen::Quaterniond(T_world_node.linear()).normalized();
  const Eigen::Vector3d t = T_world_node.translation();
  nodes_.push_back({t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()});
  return nodes_.size() - 1;
}

void PoseGraph::add_edge(const PoseGraphEdge& edge) {
  if (edge.from >= size() || edge.to >= size() || edge.from == edge.to)
    throw Error("pose graph: edge " + std::to_string(edge.from) + " -> " +
                std::to_string(edge.to) + " does not join two distinct existing nodes");
  edges_.push_back(edge);
}

void PoseGraph::add_odometry_edge(std::size_t from, std::size_t to,
                                  const Eigen::Isometry3d& T_from_to,
                                  const PoseGraphConfig& config) {
  add_edge({from, to, T_from_to,
            sqrt_information_from_sigmas(config.odometry_rotation_sigma_rad,
                                         config.odometry_translation_sigma_m),
            false});
}

void PoseGraph::add_loop_edge(std::size_t from, std::size_t to, const Eigen::Isometry3d& T_from_to,
                              const PoseGraphConfig& config) {
  add_edge({from, to, T_from_to,
            sqrt_information_from_sigmas(config.loop_rotation_sigma_rad,
                                         config.loop_translation_sigma_m),
            true});
}

std::size_t PoseGraph::loop_edge_count() const {
  std::size_t n = 0;
  for (const auto& e : edges_) n += e.is_loop && e.active;
  return n;
}

double PoseGraph::edge_chi2(std::size_t edge) const {
  const PoseGraphEdge& e = edges_.at(edge);
  const RelativePoseCost cost(e.T_from_to, e.sqrt_information);
  const double* params[2] = {nodes_[e.from].data(), nodes_[e.to].data()};
  Vector6d r;
  cost.Evaluate(params, r.data(), nullptr);
  return r.squaredNorm();
}

std::size_t PoseGraph::worst_loop(double min_chi2, std::size_t first_free_node,
                                  const std::vector<char>* confirmed,
                                  double confirmed_max_chi2) const {
  std::size_t worst = edges_.size();
  double worst_chi2 = min_chi2;
  for (std::size_t i = 0; i < edges_.size(); ++i) {
    if (!edges_[i].is_loop || !edges_[i].active || !in_window(edges_[i], first_free_node)) continue;
    const double chi2 = edge_chi2(i);
    if (confirmed && (*confirmed)[i] && chi2 <= confirmed_max_chi2) continue;
    if (chi2 > worst_chi2) {
      worst_chi2 = chi2;
      worst = i;
    }
  }
  return worst;
}

std::vector<char> PoseGraph::confirmed_loops(const PoseGraphConfig& config) const {
  const std::vector<std::size_t>& support = support_.update(edges_, size(), config);
  std::vector<char> confirmed(edges_.size(), 0);
  if (config.loop_support_min <= 0) return confirmed;
  for (std::size_t i = 0; i < edges_.size(); ++i)
    confirmed[i] = support[i] >= static_cast<std::size_t>(config.loop_support_min);
  return confirmed;
}

PoseGraphReport PoseGraph::optimize(const PoseGraphConfig& config, std::size_t first_free_node) {
  Stopwatch watch;
  // Loops that their neighbours confirm are trusted over the odometry chain: one switched off
  // before its neighbours arrived is given back now, and none is judged or robustified below.
  const std::vector<char> confirmed = confirmed_loops(config);
  held_off_.resize(edges_.size(), 0);
  std::vector<std::size_t> given_back;
  for (std::size_t i = 0; i < edges_.size(); ++i) {
    if (!confirmed[i] || edges_[i].active || held_off_[i]) continue;
    edges_[i].active = true;
    given_back.push_back(i);
  }
  // Least squares first: a bounded kernel from the drifted start would treat a genuine first
  // loop (metres of discrepancy) as an outlier. Inconsistent loops are pruned, then the
  // Cauchy kernel polishes from the closed configuration, where true loops fit well.
  PoseGraphReport report = solve_once(config, nullptr, first_free_node);
  report.restored_edges = std::move(given_back);
  report.confirmed_loops =
      static_cast<std::size_t>(std::count(confirmed.begin(), confirmed.end(), char{1}));
  // A window cannot judge a loop: its anchored nodes may carry drift that only freeing them
  // would remove, so a true loop can misfit there and would be switched off for good. When a
  // loop misfits in the window (a confirmed one too: the window may be what holds it open),
  // the whole graph is solved and judges it instead.
  const double confirmed_max_chi2 = config.loop_support_max_chi2;
  if (first_free_node > 0 &&
      worst_loop(config.loop_outlier_chi2, first_free_node, nullptr, 0) < edges_.size()) {
    first_free_node = 0;
    report.escalated = true;
    report.iterations += solve_once(config, nullptr, 0).iterations;
  }
  report.first_free_node = first_free_node;
  // Switch off the worst inconsistent loop only, then solve again: one false loop can make its
  // true neighbours look bad until it is gone.
  // A confirmed loop is judged too when it misfits grossly (loop_support_max_chi2).
  std::size_t worst =
      worst_loop(config.loop_outlier_chi2, first_free_node, &confirmed, confirmed_max_chi2);
  for (int round = 0; round < config.max_outlier_rounds && worst < edges_.size(); ++round) {
    edges_[worst].active = false;
    held_off_[worst] = confirmed[worst];  // not given back for its confirmation alone
    // One given back above and off again was off before this solve: neither, in the report.
    const auto given_back = std::find(report.restored_edges.begin(), report.restored_edges.end(), worst);
    if (given_back != report.restored_edges.end())
      report.restored_edges.erase(given_back);
    else
      report.rejected_edges.push_back(worst);
    report.iterations += solve_once(config, nullptr, first_free_node).iterations;
    worst = worst_loop(config.loop_outlier_chi2, first_free_node, &confirmed, confirmed_max_chi2);
  }
  // A false loop can pull a true neighbour further out than itself, so the neighbour goes off
  // first, in this solve or an earlier one; once the false one is off too, the neighbour fits
  // again and is given back.
  bool restored = false;
  for (std::size_t i = 0; i < edges_.size(); ++i) {
    if (!edges_[i].is_loop || edges_[i].active || !in_window(edges_[i], first_free_node)) continue;
    if (edge_chi2(i) >= config.loop_outlier_chi2) continue;
    edges_[i].active = restored = true;
    held_off_[i] = 0;
    const auto rejected = std::find(report.rejected_edges.begin(), report.rejected_edges.end(), i);
    if (rejected != report.rejected_edges.end())
      report.rejected_edges.erase(rejected);
    else
      report.restored_edges.push_back(i);
  }
  if (restored) report.iterations += solve_once(config, nullptr, first_free_node).iterations;
  // Where every loop fits well within the kernel's scale the Cauchy solution is the
  // least-squares one to within tolerance: skip the extra solve.
  const double polish_chi2 = 0.25 * config.loop_cauchy_scale * config.loop_cauchy_scale;
  if (worst_loop(polish_chi2, first_free_node, &confirmed, std::numeric_limits<double>::infinity()) <
      edges_.size()) {
    const PoseGraphReport polished = solve_once(config, &confirmed, first_free_node);
    report.iterations += polished.iterations;
    report.final_cost = polished.final_cost;
    report.converged = polished.converged;
  }
  report.solve_ms = watch.elapsed_ms();
  return report;
}

PoseGraphReport PoseGraph::solve_once(const PoseGraphConfig& config,
                                      const std::vector<char>* robust_except,
                                      std::size_t first_free_node) {
  PoseGraphReport report;
  if (size() < 2 || edges_.empty()) return report;
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  PoseManifold manifold;
  ceres::CauchyLoss loop_loss(config.loop_cauchy_scale);
  // With robust_except, loops take the Cauchy kernel except those it marks (confirmed loops).
  auto robust = [&](const PoseGraphEdge& e) {
    return robust_except && e.is_loop && !(*robust_except)[static_cast<std::size_t>(&e - edges_.data())];
  };
  for (const auto& e : edges_) {
    if (!e.active || !in_window(e, first_free_node)) continue;
    problem.AddResidualBlock(new RelativePoseCost(e.T_from_to, e.sqrt_information),
                             robust(e) ? &loop_loss : nullptr, nodes_[e.from].data(),
                             nodes_[e.to].data());
  }
  for (auto& node : nodes_)
    if (problem.HasParameterBlock(node.data())) problem.SetManifold(node.data(), &manifold);
  // Node 0 anchors the map (gauge freedom); a window is anchored by the nodes before it.
  for (std::size_t i = 0; i < std::max<std::size_t>(first_free_node, 1) && i < size(); ++i)
    if (problem.HasParameterBlock(nodes_[i].data())) problem.SetParameterBlockConstant(nodes_[i].data());
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = config.max_iterations;
  options.num_threads = 1;  // the other core runs the odometry
  // Dogleg rather than Levenberg-Marquardt: a pose graph started from odometry is close enough
  // to quadratic that the Gauss-Newton step is nearly always taken, and LM's damping from its
  // default radius costs extra factorizations (2000 keyframes, 50 loops: 14 -> 9 iterations).
  // Dogleg's few long steps stop on Ceres' default 1e-6 cost change ~1 cm short of LM's
  // answer on a 5000-keyframe window; 1e-8 gives LM's answer for one more iteration.
  options.trust_region_strategy_type = ceres::DOGLEG;
  options.function_tolerance = 1e-8;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  report.iterations = static_cast<int>(summary.iterations.size());
  report.initial_cost = summary.initial_cost;
  report.final_cost = summary.final_cost;
  report.converged = summary.termination_type == ceres::CONVERGENCE;
  return report;
}

Eigen::Isometry3d PoseGraph::pose(std::size_t node) const {
  const double* x = nodes_.at(node).data();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = node_rotation(x).normalized().toRotationMatrix();
  T.translation() = node_position(x);
  return T;
}

PoseList PoseGraph::poses() const {
  PoseList out;
  out.reserve(size());
  for (std::size_t i = 0; i < size(); ++i) out.push_back(pose(i));
  return out;
}

void PoseGraph::write_g2o(const std::filesystem::path& path) const {
  write_file_atomic(path, [&](std::ostream& out) {
    char buf[512];
    for (std::size_t i = 0; i < size(); ++i) {
      const double* x = nodes_[i].data();
      std::snprintf(buf, sizeof buf, "VERTEX_SE3:QUAT %zu %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", i,
                    x[0], x[1], x[2], x[3], x[4], x[5], x[6]);
      out << buf;
    }
    if (size() > 0) out << "FIX 0\n";
    // Our residual is [rotation; translation]; g2o orders its information [translation; rotation]
    // and measures rotation error as vec(q) ~ Log(R) / 2, hence the factor 2 on rotation rows.
    Matrix6d to_g2o = Matrix6d::Zero();
    to_g2o.block<3, 3>(0, 3).setIdentity();
    to_g2o.block<3, 3>(3, 0) = 2.0 * Eigen::Matrix3d::Identity();
    for (const auto& e : edges_) {
      if (!e.active) continue;
      const Eigen::Vector3d t = e.T_from_to.translation();
      const Eigen::Quaterniond q(e.T_from_to.linear());
      // Information in our residual r = P r_g2o, so Omega_g2o = P^T Omega P.
      const Matrix6d omega = e.sqrt_information.transpose() * e.sqrt_information;
      const Matrix6d P = to_g2o.transpose();  // r_ours = P * r_g2o
      const Matrix6d info = P.transpose() * omega * P;
      std::snprintf(buf, sizeof buf, "EDGE_SE3:QUAT %zu %zu %.9f %.9f %.9f %.9f %.9f %.9f %.9f",
                    e.from, e.to, t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
      out << buf;
      for (int r = 0; r < 6; ++r)
        for (int c = r; c < 6; ++c) {
          std::snprintf(buf, sizeof buf, " %.9g", info(r, c));
          out << buf;
        }
      out << "\n";
    }
  });
}

}  // namespace scfloam
