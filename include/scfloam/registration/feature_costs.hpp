// Point-to-line and point-to-plane residuals with analytic Jacobians, and the Ceres cost that
// evaluates all of a round's matches in one residual block (one block per match costs Ceres
// ~10x more in bookkeeping than the arithmetic itself at ~10^4 matches per frame).
#pragma once

#include <ceres/cost_function.h>

#include <tbb/task_arena.h>

#include <Eigen/Core>
#include <vector>

namespace scfloam {

// An edge point and the map line it matched: residual = component of (T p - line_point)
// perpendicular to line_dir (a 3-vector whose norm is the point-to-line distance).
struct EdgeMatch {
  Eigen::Vector3d point_lidar;
  Eigen::Vector3d line_point;
  Eigen::Vector3d line_dir;  // unit
};

// A plane point and the map plane it matched: residual = normal . (T p) + offset.
struct PlaneMatch {
  Eigen::Vector3d point_lidar;
  Eigen::Vector3d normal;  // unit
  double offset = 0;
};

using Jacobian16 = Eigen::Matrix<double, 1, 6>;
using Jacobian36 = Eigen::Matrix<double, 3, 6>;

// Residuals at pose (R, t) and, when J is not null, their derivative with respect to the
// tangent delta = [omega; v] of PoseManifold.
Eigen::Vector3d edge_residual(const EdgeMatch& m, const Eigen::Matrix3d& R,
                              const Eigen::Vector3d& t, Jacobian36* J);
double plane_residual(const PlaneMatch& m, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                      Jacobian16* J);

// Orthonormal rows spanning the plane perpendicular to the unit vector `dir`.
Eigen::Matrix<double, 2, 3> perpendicular_basis(const Eigen::Vector3d& dir);

// Huber loss folded into the residual: r <- sqrt(rho(|r|^2)) r / |r|, so that the squared
// norm equals Huber's rho(s) = s for s <= delta^2, 2 delta sqrt(s) - delta^2 above; J is
// transformed with the exact derivative. Keeps the loss per match inside one residual block.
template <int Rows>
void robustify_huber(double delta, Eigen::Matrix<double, Rows, 1>& r,
                     Eigen::Matrix<double, Rows, 6>* J) {
  const double m = r.norm();
  if (delta <= 0 || m <= delta) return;  // delta 0: plain least squares (no loss)
  const double rho = 2 * delta * m - delta * delta;
  const double g = std::sqrt(rho) / m;      // scale perpendicular to r
  const double a = delta / std::sqrt(rho);  // d|r~|/d|r| along r
  if (J) {
    const Eigen::Matrix<double, Rows, 1> u = r / m;
    *J = g * *J + (a - g) * u * (u.transpose() * *J);
  }
  r *= g;
}

// All matches of one correspondence round as one residual block on the 7-double pose block:
// two rows per edge (the point-to-line vector in a basis perpendicular to the line), one per
// plane, each robustified.
class FeatureCost : public ceres::CostFunction {
 public:
  FeatureCost(const std::vector<EdgeMatch>& edges, const std::vector<PlaneMatch>& planes,
              double huber_delta_m);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const std::vector<EdgeMatch>& edges_;
  const std::vector<PlaneMatch>& planes_;
  double delta_;
};

// The objective of FeatureCost handed to Ceres as 7 rows instead of one or two per match.
// With H = J^T J = V diag(l) V^T and g = J^T r of all the (robustified) match rows, the rows
// J~ = diag(sqrt l) V^T and r~ = diag(1/sqrt l) V^T g give J~^T J~ = H and J~^T r~ = g, and a
// 7th row with zero Jacobian carries the rest of |r|^2, so the cost is the same too: every
// quantity Ceres' trust-region step uses (cost, gradient, Gauss-Newton matrix, Jacobi scaling
// diag(H), model cost change) is unchanged, while its per-iteration work no longer grows with
// ~10^4 rows (its zeroing, validation, manifold product and column scaling of the dense
// Jacobian were a third of a frame). The matches are summed in fixed blocks, in parallel on
// `arena` when given, then in block order: the result does not depend on the thread count.
class NormalEquationCost : public ceres::CostFunction {
 public:
  NormalEquationCost(const std::vector<EdgeMatch>& edges, const std::vector<PlaneMatch>& planes,
                     double huber_delta_m, tbb::task_arena* arena = nullptr);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // Sum over the match rows at pose (R, t): |r|^2, and when wanted J^T J and J^T r.
  struct Sums {
    Eigen::Matrix<double, 6, 6> H;
    Eigen::Matrix<double, 6, 1> g;
    double squared_norm = 0;
  };
  void sums(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, bool with_jacobian,
            Sums& out) const;

 private:
  const std::vector<EdgeMatch>& edges_;
  const std::vector<PlaneMatch>& planes_;
  double delta_;
  tbb::task_arena* arena_;
  std::vector<Eigen::Matrix<double, 2, 3>> edge_bases_;  // perpendicular_basis of each line
  // Per-block partial sums: upper triangle of J^T J (21), J^T r (6), |r|^2.
  struct Partial {
    double H[21], g[6], squared_norm;
  };
  mutable std::vector<Partial> blocks_;
};

}  // namespace scfloam
