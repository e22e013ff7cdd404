// Small SE(3)/SO(3) helpers on Eigen types.
#pragma once

#include <Eigen/Geometry>

namespace scfloam {

// Rotation vector (axis * angle) -> rotation matrix, exact for all angles.
Eigen::Matrix3d so3_exp(const Eigen::Vector3d& omega);
// Rotation matrix -> rotation vector, angle in [0, pi].
Eigen::Vector3d so3_log(const Eigen::Matrix3d& R);
// Skew-symmetric matrix [v]x with [v]x w = v x w.
Eigen::Matrix3d skew(const Eigen::Vector3d& v);
// Angle of a rotation in radians, in [0, pi], robust near 0 and pi.
double rotation_angle_rad(const Eigen::Matrix3d& R);
// Project the linear part back onto SO(3) (nearest rotation); keeps poses on the manifold
// when they are composed many times (F-LOAM's Eigen 3.4 drift, see docs).
Eigen::Isometry3d orthonormalized(const Eigen::Isometry3d& T);
// Pose from a 6-vector [rotation vector; translation] applied on the left: exp(xi) * T.
Eigen::Isometry3d left_perturb(const Eigen::Matrix<double, 6, 1>& xi, const Eigen::Isometry3d& T);
// Linear interpolation of translation and slerp of rotation, alpha in [0, 1].
Eigen::Isometry3d interpolate(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double alpha);

}  // namespace scfloam
