// The relative degeneracy test (registration/degeneracy.hpp) on Hessians built from known
// plane normals: a corridor leaves its axis weak, a box constrains everything, and the answer
// does not change with the number of matches (the reason the test is relative).
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "scfloam/registration/degeneracy.hpp"

using namespace scfloam;

namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;

// J^T J of point-to-plane residuals: each point p on a plane with unit normal n has the
// row [(p x n)^T, n^T] (tangent [omega; v]).
void add_plane_points(Matrix6& H, const Eigen::Vector3d& n, const Eigen::Vector3d& origin,
                      const Eigen::Vector3d& span_a, const Eigen::Vector3d& span_b, int count) {
  for (int i = 0; i < count; ++i) {
    const double a = (i % 10) / 9.0 - 0.5, b = (i / 10 % 10) / 9.0 - 0.5;
    const Eigen::Vector3d p = origin + a * span_a + b * span_b;
    Eigen::Matrix<double, 1, 6> J;
    J << p.cross(n).transpose(), n.transpose();
    H += J.transpose() * J;
  }
}

// A 16 m wide, 6 m high corridor along x, walls 40 m long; `bay` adds points on faces
// across the axis (normal x), like the tunnel's emergency bays.
Matrix6 corridor(int per_face, int bay) {
  Matrix6 H = Matrix6::Zero();
  const Eigen::Vector3d X(40, 0, 0), Y(0, 16, 0), Z(0, 0, 6);
  add_plane_points(H, Eigen::Vector3d::UnitZ(), {0, 0, -1.7}, X, Y, per_face);  // floor
  add_plane_points(H, -Eigen::Vector3d::UnitZ(), {0, 0, 4.3}, X, Y, per_face);  // ceiling
  add_plane_points(H, Eigen::Vector3d::UnitY(), {0, -8, 1.3}, X, Z, per_face);  // walls
  add_plane_points(H, -Eigen::Vector3d::UnitY(), {0, 8, 1.3}, X, Z, per_face);
  if (bay > 0) add_plane_points(H, Eigen::Vector3d::UnitX(), {12, 8, 0}, Y / 4, Z / 4, bay);
  return H;
}

}  // namespace

TEST(Degeneracy, CorridorAxisIsTheWeakTranslation) {
  const RegistrationConfig config;
  const Degeneracy d(corridor(400, 10), config);
  EXPECT_EQ(d.weak_tra, 1);
  EXPECT_NEAR(std::abs(d.tra_vectors.col(0).x()), 1.0, 1e-6);  // the axis
  // The weak basis spans exactly the axis; the strong one is orthogonal to it.
  const auto weak = d.basis(false), strong = d.basis(true);
  ASSERT_EQ(weak.cols(), d.weak());
  ASSERT_EQ(strong.cols(), 6 - d.weak());
  EXPECT_LT((weak.transpose() * strong).norm(), 1e-9);
}

TEST(Degeneracy, RelativeTestIgnoresTheNumberOfMatches) {
  // Ten times the points: every eigenvalue grows tenfold, the verdict stays.
  const RegistrationConfig config;
  for (int per_face : {200, 2000}) {
    const Degeneracy d(corridor(per_face, per_face / 40), config);
    EXPECT_EQ(d.weak_tra, 1) << per_face;
  }
  // Under the old absolute test (eigenvalue < 50) the large corridor passed: its axis
  // eigenvalue is far above 50 although it is a corridor.
  EXPECT_GT(Degeneracy(corridor(2000, 100), config).tra_values[0], 50.0);
}

TEST(Degeneracy, BoxIsWellConstrained) {
  Matrix6 H = corridor(400, 0);
  add_plane_points(H, -Eigen::Vector3d::UnitX(), {20, 0, 1.3}, {0, 16, 0}, {0, 0, 6}, 400);
  add_plane_points(H, Eigen::Vector3d::UnitX(), {-20, 0, 1.3}, {0, 16, 0}, {0, 0, 6}, 400);
  const Degeneracy d(H, RegistrationConfig{});
  EXPECT_EQ(d.weak(), 0);
  EXPECT_EQ(d.basis(true).cols(), 6);
}

TEST(Degeneracy, NoInformationIsWeakEverywhere) {
  const Degeneracy d(Matrix6::Zero(), RegistrationConfig{});
  EXPECT_EQ(d.weak(), 6);
}
