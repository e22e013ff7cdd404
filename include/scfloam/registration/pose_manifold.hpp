// The pose parameter block and its Ceres 2.1 manifold.
//
// Block layout (7 doubles): quaternion x, y, z, w (Eigen's coeffs order), translation x, y, z.
// Tangent (6): delta = [omega; v], applied as R' = exp(omega) * R, t' = t + v. Rotating about
// the sensor's position rather than the world origin keeps the rotation and translation
// columns of the Jacobian decoupled even far from the origin.
//
// Jacobian convention (the usual trick of F-LOAM and others, stated here so nobody is
// surprised): cost functions write d r / d delta into the first 6 of their 7 "ambient"
// columns and zero into the 7th, and PlusJacobian is [I_6; 0]. Ceres multiplies the two, so
// the solver sees exactly d r / d delta; tests/registration checks it against numerical
// differentiation through Plus.
#pragma once

#include <ceres/manifold.h>

#include <Eigen/Geometry>

namespace scfloam {

class PoseManifold : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

// PoseManifold restricted to a subspace of its tangent: delta = B a, with B's columns an
// orthonormal basis (6 x m, 1 <= m <= 6) of the directions the solver may move in. Used when
// the scan-to-map problem is degenerate and a block's prior weight is 0: its weak directions
// keep the prediction (solution remapping, Zhang et al. 2016). With the default weights the
// prediction is a prior there instead (scan_to_map.cpp, WeakDirectionPrior).
class SubspacePoseManifold : public ceres::Manifold {
 public:
  explicit SubspacePoseManifold(const Eigen::Matrix<double, 6, Eigen::Dynamic>& basis)
      : basis_(basis) {}
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return static_cast<int>(basis_.cols()); }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;

 private:
  Eigen::Matrix<double, 6, Eigen::Dynamic> basis_;
  PoseManifold full_;
};

void pose_to_block(const Eigen::Isometry3d& T, double* block);
Eigen::Isometry3d block_to_pose(const double* block);  // re-normalises the quaternion

}  // namespace scfloam
