// Ceres pieces of the pose graph, in their own header so that tests can check the analytic
// Jacobians against numeric differentiation.
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Geometry>

#include "scfloam/se3.hpp"

namespace scfloam::pose_graph_detail {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

inline Eigen::Vector3d node_position(const double* x) { return Eigen::Vector3d(x[0], x[1], x[2]); }
inline Eigen::Quaterniond node_rotation(const double* x) {
  return Eigen::Quaterniond(x[6], x[3], x[4], x[5]);
}

// Inverse of SO(3)'s right Jacobian: d Log(R Exp(d)) / d d at d = 0.
inline Eigen::Matrix3d right_jacobian_inverse(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  const Eigen::Matrix3d W = skew(phi);
  if (angle < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * W;
  const double cot_term = (1.0 / (angle * angle)) - (1.0 + std::cos(angle)) / (2.0 * angle * std::sin(angle));
  return Eigen::Matrix3d::Identity() + 0.5 * W + cot_term * W * W;
}

// Node update on the right: t' = t + dt, R' = R Exp(dtheta); tangent ordered [dt; dtheta].
// The PlusJacobian below is the "lifted" one ([I6; 0] in ambient order t, q.xyz, q.w): the cost
// function then returns tangent Jacobians directly in its first six columns (and zero for q.w),
// which keeps the Jacobians analytic and cheap.
class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    const Eigen::Quaterniond q =
        (node_rotation(x) * Eigen::Quaterniond(so3_exp(Eigen::Vector3d(delta[3], delta[4], delta[5]))))
            .normalized();
    for (int i = 0; i < 3; ++i) x_plus_delta[i] = x[i] + delta[i];
    x_plus_delta[3] = q.x();
    x_plus_delta[4] = q.y();
    x_plus_delta[5] = q.z();
    x_plus_delta[6] = q.w();
    return true;
  }
  bool PlusJacobian(const double*, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.topRows<6>().setIdentity();
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    for (int i = 0; i < 3; ++i) y_minus_x[i] = y[i] - x[i];
    const Eigen::Vector3d dtheta =
        so3_log((node_rotation(x).conjugate() * node_rotation(y)).toRotationMatrix());
    for (int i = 0; i < 3; ++i) y_minus_x[3 + i] = dtheta[i];
    return true;
  }
  bool MinusJacobian(const double*, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.leftCols<6>().setIdentity();
    return true;
  }
};

// Whitened residual [Log(R_E); t_E] of E = Z^-1 (T_a^-1 T_b) and its analytic Jacobians
// with respect to the right-perturbation tangents [dt; dtheta] of nodes a and b.
class RelativePoseCost final : public ceres::SizedCostFunction<6, 7, 7> {
 public:
  RelativePoseCost(const Eigen::Isometry3d& measured, const Matrix6d& sqrt_information)
      : R_z_t_(measured.linear().transpose()),
        t_z_(measured.translation()),
        sqrt_information_(sqrt_information) {}

  bool Evaluate(const double* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Matrix3d R_a = node_rotation(parameters[0]).toRotationMatrix();
    const Eigen::Matrix3d R_b = node_rotation(parameters[1]).toRotationMatrix();
    const Eigen::Vector3d v = R_a.transpose() * (node_position(parameters[1]) - node_position(parameters[0]));
    const Eigen::Matrix3d R_e = R_z_t_ * R_a.transpose() * R_b;
    const Eigen::Vector3d r_rot = so3_log(R_e);
    Vector6d r;
    r << r_rot, R_z_t_ * (v - t_z_);
    Eigen::Map<Vector6d> whitened(residuals);
    whitened = sqrt_information_ * r;
    if (!jacobians) return true;
    const Eigen::Matrix3d Jr_inv = right_jacobian_inverse(r_rot);
    if (jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobians[0]);
      Matrix6d J_tangent = Matrix6d::Zero();
      J_tangent.block<3, 3>(0, 3) = -Jr_inv * R_b.transpose() * R_a;  // rotation wrt dtheta_a
      J_tangent.block<3, 3>(3, 0) = -R_z_t_ * R_a.transpose();        // translation wrt dt_a
      J_tangent.block<3, 3>(3, 3) = R_z_t_ * skew(v);                 // translation wrt dtheta_a
      J.leftCols<6>() = sqrt_information_ * J_tangent;
      J.col(6).setZero();
    }
    if (jacobians[1]) {
      Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobians[1]);
      Matrix6d J_tangent = Matrix6d::Zero();
      J_tangent.block<3, 3>(0, 3) = Jr_inv;                      // rotation wrt dtheta_b
      J_tangent.block<3, 3>(3, 0) = R_z_t_ * R_a.transpose();    // translation wrt dt_b
      J.leftCols<6>() = sqrt_information_ * J_tangent;
      J.col(6).setZero();
    }
    return true;
  }

 private:
  Eigen::Matrix3d R_z_t_;
  Eigen::Vector3d t_z_;
  Matrix6d sqrt_information_;
};

}  // namespace scfloam::pose_graph_detail
