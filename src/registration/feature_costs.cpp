#include "scfloam/registration/feature_costs.hpp"

#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace scfloam {

Eigen::Vector3d edge_residual(const EdgeMatch& m, const Eigen::Matrix3d& R,
                              const Eigen::Vector3d& t, Jacobian36* J) {
  const Eigen::Vector3d Rp = R * m.point_lidar;
  const Eigen::Vector3d d = Rp + t - m.line_point;
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - m.line_dir * m.line_dir.transpose();
  if (J) {
    // d(Rp)/d omega = -[Rp]x for R' = exp(omega) R; d t / d v = I.
    J->leftCols<3>() = -P * (Eigen::Matrix3d() << 0, -Rp.z(), Rp.y(), Rp.z(), 0, -Rp.x(),
                             -Rp.y(), Rp.x(), 0).finished();
    J->rightCols<3>() = P;
  }
  return P * d;
}

double plane_residual(const PlaneMatch& m, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                      Jacobian16* J) {
  const Eigen::Vector3d Rp = R * m.point_lidar;
  if (J) {
    J->leftCols<3>() = Rp.cross(m.normal).transpose();  // -n^T [Rp]x
    J->rightCols<3>() = m.normal.transpose();
  }
  return m.normal.dot(Rp + t) + m.offset;
}

Eigen::Matrix<double, 2, 3> perpendicular_basis(const Eigen::Vector3d& dir) {
  const Eigen::Vector3d helper =
      std::abs(dir.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d e1 = helper.cross(dir).normalized();
  Eigen::Matrix<double, 2, 3> E;
  E.row(0) = e1.transpose();
  E.row(1) = dir.cross(e1).transpose();
  return E;
}

FeatureCost::FeatureCost(const std::vector<EdgeMatch>& edges,
                         const std::vector<PlaneMatch>& planes, double huber_delta_m)
    : edges_(edges), planes_(planes), delta_(huber_delta_m) {
  set_num_residuals(static_cast<int>(2 * edges.size() + planes.size()));
  mutable_parameter_block_sizes()->push_back(7);
}

bool FeatureCost::Evaluate(double const* const* parameters, double* residuals,
                           double** jacobians) const {
  const Eigen::Quaterniond q = Eigen::Map<const Eigen::Quaterniond>(parameters[0]).normalized();
  const Eigen::Matrix3d R = q.toRotationMatrix();
  const Eigen::Map<const Eigen::Vector3d> t(parameters[0] + 4);
  double* J = (jacobians && jacobians[0]) ? jacobians[0] : nullptr;  // row-major rows x 7
  std::size_t row = 0;
  for (const auto& m : edges_) {
    // The residual lies in the plane perpendicular to the line: its coordinates in an
    // orthonormal basis of that plane have the same norm and give the same J^T J in two rows
    // instead of three (Ceres' work per iteration grows with the rows).
    Jacobian36 J3;
    const Eigen::Vector3d r3 = edge_residual(m, R, t, J ? &J3 : nullptr);
    const Eigen::Matrix<double, 2, 3> E = perpendicular_basis(m.line_dir);
    Eigen::Vector2d r = E * r3;
    Eigen::Matrix<double, 2, 6> Je;
    if (J) Je.noalias() = E * J3;
    robustify_huber<2>(delta_, r, J ? &Je : nullptr);
    for (int i = 0; i < 2; ++i, ++row) {
      residuals[row] = r[i];
      if (J) {
        Eigen::Map<Eigen::Matrix<double, 1, 7>> Jrow(J + 7 * row);
        Jrow << Je.row(i), 0.0;
      }
    }
  }
  for (const auto& m : planes_) {
    Jacobian16 Jp;
    Eigen::Matrix<double, 1, 1> r(plane_residual(m, R, t, J ? &Jp : nullptr));
    robustify_huber<1>(delta_, r, J ? &Jp : nullptr);
    residuals[row] = r[0];
    if (J) {
      Eigen::Map<Eigen::Matrix<double, 1, 7>> Jrow(J + 7 * row);
      Jrow << Jp, 0.0;
    }
    ++row;
  }
  return true;
}

NormalEquationCost::NormalEquationCost(const std::vector<EdgeMatch>& edges,
                                       const std::vector<PlaneMatch>& planes,
                                       double huber_delta_m, tbb::task_arena* arena)
    : edges_(edges), planes_(planes), delta_(huber_delta_m), arena_(arena) {
  set_num_residuals(7);
  mutable_parameter_block_sizes()->push_back(7);
  edge_bases_.resize(edges.size());
  for (std::size_t i = 0; i < edges.size(); ++i) edge_bases_[i] = perpendicular_basis(edges[i].line_dir);
}

namespace {

// One residual row r with Jacobian row j (tangent [omega; v]) added to the upper triangle of
// J^T J (H, 21 entries) and to J^T r (g).
template <typename Row>
inline void add_row(const Row& j, double r, double* H, double* g) {
  int k = 0;
  for (int a = 0; a < 6; ++a) {
    g[a] += j[a] * r;
    for (int b = a; b < 6; ++b) H[k++] += j[a] * j[b];
  }
}

}  // namespace

void NormalEquationCost::sums(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                              bool with_jacobian, Sums& out) const {
  // Fixed blocks summed in block order: the same floating-point sums whatever the threads.
  constexpr std::size_t kBlock = 1024;
  const std::size_t n_edges = edges_.size(), total = n_edges + planes_.size();
  const std::size_t n_blocks = (total + kBlock - 1) / kBlock;
  blocks_.resize(n_blocks);
  auto run_block = [&](std::size_t b) {
    Partial& s = blocks_[b];
    std::fill(s.H, s.H + 21, 0.0);
    std::fill(s.g, s.g + 6, 0.0);
    double squared_norm = 0;
    const std::size_t begin = b * kBlock, end = std::min(total, begin + kBlock);
    for (std::size_t i = begin; i < std::min(end, n_edges); ++i) {
      // The point-to-line vector in the line's perpendicular basis E (two rows, as FeatureCost):
      // row k is e_k . (Rp + t - c), its Jacobian [(Rp x e_k)^T, e_k^T] (edge_residual's, times E).
      const EdgeMatch& m = edges_[i];
      const Eigen::Matrix<double, 2, 3>& E = edge_bases_[i];
      const Eigen::Vector3d Rp = R * m.point_lidar;
      Eigen::Vector2d r = E * (Rp + t - m.line_point);
      Eigen::Matrix<double, 2, 6> J;
      if (with_jacobian)
        for (int k = 0; k < 2; ++k) {
          J.block<1, 3>(k, 0) = Rp.cross(E.row(k).transpose()).transpose();
          J.block<1, 3>(k, 3) = E.row(k);
        }
      robustify_huber<2>(delta_, r, with_jacobian ? &J : nullptr);
      squared_norm += r.squaredNorm();
      if (!with_jacobian) continue;
      add_row(J.row(0), r[0], s.H, s.g);
      add_row(J.row(1), r[1], s.H, s.g);
    }
    for (std::size_t i = std::max(begin, n_edges); i < end; ++i) {
      Jacobian16 J;
      Eigen::Matrix<double, 1, 1> r(
          plane_residual(planes_[i - n_edges], R, t, with_jacobian ? &J : nullptr));
      robustify_huber<1>(delta_, r, with_jacobian ? &J : nullptr);
      squared_norm += r[0] * r[0];
      if (with_jacobian) add_row(J, r[0], s.H, s.g);
    }
    s.squared_norm = squared_norm;
  };
  if (arena_ && n_blocks > 1)
    arena_->execute([&] { tbb::parallel_for(std::size_t{0}, n_blocks, run_block); });
  else
    for (std::size_t b = 0; b < n_blocks; ++b) run_block(b);
  double H[21] = {}, g[6] = {};
  out.squared_norm = 0;
  for (const Partial& s : blocks_) {
    for (int k = 0; k < 21; ++k) H[k] += s.H[k];
    for (int k = 0; k < 6; ++k) g[k] += s.g[k];
    out.squared_norm += s.squared_norm;
  }
  int k = 0;
  for (int a = 0; a < 6; ++a) {
    out.g[a] = g[a];
    for (int b = a; b < 6; ++b) out.H(a, b) = out.H(b, a) = H[k++];
  }
}

bool NormalEquationCost::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const Eigen::Quaterniond q = Eigen::Map<const Eigen::Quaterniond>(parameters[0]).normalized();
  const Eigen::Matrix3d R = q.toRotationMatrix();
  const Eigen::Map<const Eigen::Vector3d> t(parameters[0] + 4);
  double* J = (jacobians && jacobians[0]) ? jacobians[0] : nullptr;  // row-major 7 x 7
  Sums s;
  sums(R, t, J != nullptr, s);
  if (!std::isfinite(s.squared_norm)) return false;
  std::fill(residuals, residuals + 7, 0.0);
  if (!J) {  // only the cost is wanted
    residuals[6] = std::sqrt(s.squared_norm);
    return true;
  }
  if (!s.H.allFinite() || !s.g.allFinite()) return false;
  Eigen::Map<Eigen::Matrix<double, 7, 7, Eigen::RowMajor>> Jm(J);
  Jm.setZero();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(s.H);
  const Eigen::Matrix<double, 6, 1> Vg = es.eigenvectors().transpose() * s.g;
  // g lies in the range of H; directions with a (numerically) zero eigenvalue carry nothing.
  const double floor = 1e-12 * std::max(es.eigenvalues().maxCoeff(), 0.0);
  double explained = 0;
  for (int i = 0; i < 6; ++i) {
    const double l = es.eigenvalues()[i];
    if (!(l > floor) || l <= 0) continue;
    const double sl = std::sqrt(l);
    Jm.block<1, 6>(i, 0) = sl * es.eigenvectors().col(i).transpose();
    residuals[i] = Vg[i] / sl;
    explained += residuals[i] * residuals[i];
  }
  residuals[6] = std::sqrt(std::max(0.0, s.squared_norm - explained));
  return true;
}

}  // namespace scfloam
