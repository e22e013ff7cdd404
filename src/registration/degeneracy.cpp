#include "scfloam/registration/degeneracy.hpp"

#include <Eigen/Eigenvalues>
#include <utility>

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

Eigen::Matrix<double, 6, Eigen::Dynamic> Degeneracy::directions(Part rotation,
                                                                Part translation) const {
  // Columns [first, end) of a block's ascending eigenvectors: the weak ones come first.
  const auto range = [](Part part, int weak) -> std::pair<int, int> {
    switch (part) {
      case Part::kWeak: return {0, weak};
      case Part::kStrong: return {weak, 3};
      case Part::kAll: return {0, 3};
      case Part::kNone: break;
    }
    return {0, 0};
  };
  const auto [r0, r1] = range(rotation, weak_rot);
  const auto [t0, t1] = range(translation, weak_tra);
  const int nr = r1 - r0;
  Eigen::Matrix<double, 6, Eigen::Dynamic> B = Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, nr + t1 - t0);
  for (int i = r0; i < r1; ++i) B.block<3, 1>(0, i - r0) = rot_vectors.col(i);
  for (int i = t0; i < t1; ++i) B.block<3, 1>(3, nr + i - t0) = tra_vectors.col(i);
  return B;
}

}  // namespace scfloam
