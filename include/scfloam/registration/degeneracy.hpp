// Which directions of a scan-to-map solve are poorly constrained (docs/degenerate.md).
// The test is relative: an eigenvalue of the rotation or translation block of J^T J is weak
// when it is small against the block's largest one (the condition ratio), so the count of
// matches and their spread do not matter; an absolute floor still catches a near-empty scan.
#pragma once

#include <Eigen/Core>

#include "scfloam/config.hpp"

namespace scfloam {

struct Degeneracy {
  // Eigen-decomposition of the two 3x3 blocks of the 6x6 J^T J (tangent [omega; v]),
  // ascending. The blocks are analysed apart because their units differ.
  Eigen::Vector3d rot_values = Eigen::Vector3d::Zero(), tra_values = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rot_vectors = Eigen::Matrix3d::Identity(),
                  tra_vectors = Eigen::Matrix3d::Identity();
  int weak_rot = 0, weak_tra = 0;  // the weak ones are the first weak_* of each block

  Degeneracy(const Eigen::Matrix<double, 6, 6>& H, const RegistrationConfig& config);
  int weak() const { return weak_rot + weak_tra; }

  // Orthonormal 6 x m basis of chosen tangent directions: of each block none, its weak ones,
  // its strong (well-constrained) ones, or all three; rotation columns first.
  enum class Part { kNone, kWeak, kStrong, kAll };
  Eigen::Matrix<double, 6, Eigen::Dynamic> directions(Part rotation, Part translation) const;
  Eigen::Matrix<double, 6, Eigen::Dynamic> basis(bool strong) const {
    const Part p = strong ? Part::kStrong : Part::kWeak;
    return directions(p, p);
  }
};

}  // namespace scfloam
