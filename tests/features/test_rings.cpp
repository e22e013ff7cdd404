#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "scfloam/error.hpp"
#include "scfloam/features/rings.hpp"

namespace scfloam {
namespace {

TEST(Rings, Hdl64TwoBlockTable) {
  const auto m = LidarModel::hdl64;
  EXPECT_EQ(ring_from_elevation_deg(m, 2.0), 0);
  EXPECT_EQ(ring_from_elevation_deg(m, 2.0 - 1.0 / 3.0), 1);
  EXPECT_EQ(ring_from_elevation_deg(m, 2.0 - 10.0 / 3.0), 10);
  EXPECT_EQ(ring_from_elevation_deg(m, -8.83 - 0.5), 33);  // lower block, 1/2 deg spacing
  EXPECT_EQ(ring_from_elevation_deg(m, -8.83 - 15.0), 62);
  EXPECT_EQ(ring_from_elevation_deg(m, 2.1), -1);
  EXPECT_EQ(ring_from_elevation_deg(m, -24.4), -1);
}

// The feature step's float table agrees with the double one at every elevation but those
// within float rounding of a boundary between beams (or of the field's ends).
TEST(Rings, Hdl64FloatTableMatchesTheDoubleOne) {
  std::vector<double> boundaries{2.0, -24.33, -8.83};
  for (int k = 0; k < 33; ++k) boundaries.push_back(2.0 - (k + 0.5) / 3.0);
  for (int k = 0; k < 32; ++k) boundaries.push_back(-8.83 - (k + 0.5) / 2.0);
  int compared = 0;
  for (int step = 0; step <= 300000; ++step) {
    const float a = -26.0f + 0.0001f * static_cast<float>(step);
    bool near_boundary = false;
    for (double b : boundaries) near_boundary |= std::abs(a - b) < 1e-4;
    if (near_boundary) continue;
    ASSERT_EQ(ring_from_elevation_hdl64_deg(a), ring_from_elevation_deg(LidarModel::hdl64, a)) << a;
    ++compared;
  }
  EXPECT_GT(compared, 290000);
  EXPECT_EQ(ring_from_elevation_hdl64_deg(2.0f), 0);
  EXPECT_EQ(ring_from_elevation_hdl64_deg(-8.83f - 15.0f), 62);
  EXPECT_EQ(ring_from_elevation_hdl64_deg(90.0f), -1);
}

// Every beam of a uniform fan maps to its own ring, and nudges within a third of the spacing
// keep it there.
void expect_uniform_fan(LidarModel m, double lowest, double highest) {
  const int beams = num_beams(m);
  const double spacing = (highest - lowest) / (beams - 1);
  for (int b = 0; b < beams; ++b) {
    const double a = lowest + b * spacing;
    EXPECT_EQ(ring_from_elevation_deg(m, a), b) << lidar_model_name(m) << " beam " << b;
    EXPECT_EQ(ring_from_elevation_deg(m, a + spacing / 3), b);
    EXPECT_EQ(ring_from_elevation_deg(m, a - spacing / 3), b);
  }
  EXPECT_EQ(ring_from_elevation_deg(m, lowest - spacing), -1);
  EXPECT_EQ(ring_from_elevation_deg(m, highest + spacing), -1);
}

TEST(Rings, UniformPresets) {
  expect_uniform_fan(LidarModel::vlp16, -15.0, 15.0);
  expect_uniform_fan(LidarModel::hdl32, -30.67, 10.67);
  expect_uniform_fan(LidarModel::os1_64, -16.6, 16.6);
  expect_uniform_fan(LidarModel::os1_128, -22.5, 22.5);
}

TEST(Rings, ModelNamesRoundTripAndUnknownThrows) {
  for (auto m : {LidarModel::hdl64, LidarModel::hdl32, LidarModel::vlp16, LidarModel::os1_64,
                 LidarModel::os1_128})
    EXPECT_EQ(parse_lidar_model(lidar_model_name(m)), m);
  EXPECT_THROW(parse_lidar_model("hdl-64"), Error);
}

}  // namespace
}  // namespace scfloam
