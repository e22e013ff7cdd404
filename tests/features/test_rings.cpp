#include <gtest/gtest.h>

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
