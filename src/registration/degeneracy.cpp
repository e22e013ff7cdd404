#include "scfloam/registration/degeneracy.hpp"

#include <Eigen/Eigenvalues>

namespace scfloam {

namespace {

// How many of the ascending `values` are weak: below the absolute floor, or below `ratio`
// times the largest (a block with no information at all is weak in every direction).
int count_weak(const Eigen::Vector3d& values, double floor, double ratio) {
  int weak = 0;
  for (int i = 0; i < 3; ++i)
    weak += values[i] < floor || values[i] < ratio * values[2] || !(values[2] > 0);
  return weak;
}

}  // namespace

Degeneracy::Degeneracy(const Eigen::Matrix<double, 6, 6>& H, const RegistrationConfig& config) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> rot(H.topLeftCorner<3, 3>());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> tra(H.bottomRightCorner<3, 3>());
  rot_values = rot.eigenvalues();
  rot_vectors = rot.eigenvectors();
  tra_values = tra.eigenvalues();
  tra_vectors = tra.eigenvectors();
  weak_rot = count_weak(rot_values, config.degeneracy_min_rotation_eigenvalue,
                        config.degeneracy_min_rotation_ratio);
  weak_tra = count_weak(tra_values, config.degeneracy_min_eigenvalue,
                        config.degeneracy_min_translation_ratio);
}

Eigen::Matrix<double, 6, Eigen::Dynamic> Degeneracy::basis(bool strong) const {
  const int nr = strong ? 3 - weak_rot : weak_rot, nt = strong ? 3 - weak_tra : weak_tra;
  Eigen::Matrix<double, 6, Eigen::Dynamic> B = Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, nr + nt);
  const int r0 = strong ? weak_rot : 0, t0 = strong ? weak_tra : 0;
  for (int i = 0; i < nr; ++i) B.block<3, 1>(0, i) = rot_vectors.col(r0 + i);
  for (int i = 0; i < nt; ++i) B.block<3, 1>(3, nr + i) = tra_vectors.col(t0 + i);
  return B;
}

}  // namespace scfloam
