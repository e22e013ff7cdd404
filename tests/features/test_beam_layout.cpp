// Beam layouts learned from a scan's elevations (features/beam_layout.hpp) and their use by
// the feature extraction when no built-in ring table fits the sensor.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>

#include "scfloam/error.hpp"
#include "scfloam/features/beam_layout.hpp"
#include "scfloam/features/feature_extractor.hpp"
#include "test_paths.hpp"

namespace scfloam {
namespace {

// Velodyne VLP-32C: non-uniform, 1/3 deg around the horizon, 9.7 deg apart at the bottom.
const std::vector<double> kVlp32c = {15.0,   10.333, 7.0,    4.667,  3.333,  2.333,  1.667,  1.333,
                                     1.0,    0.667,  0.333,  0.0,    -0.333, -0.667, -1.0,   -1.333,
                                     -1.667, -2.0,   -2.333, -2.667, -3.0,   -3.333, -3.667, -4.0,
                                     -4.667, -5.333, -6.148, -7.254, -8.843, -11.31, -15.639, -25.0};

std::vector<double> uniform_fan(double top, double bottom, int beams) {
  std::vector<double> out;
  for (int i = 0; i < beams; ++i) out.push_back(top + (bottom - top) * i / (beams - 1));
  return out;
}

// A box room (walls x = 10, y = 12, x = -20, y = -15, floor 1.7 m below, ceiling 6 m above)
// seen by a sensor with these beam elevations (highest first), in firing order: column by
// column, all beams of a column together, as a raw driver emits them. `ring` holds the beam's
// index; `elevation_jitter_deg` blurs each return's elevation (gaussian).
std::vector<LidarPoint> room_scan(const std::vector<double>& elevations_deg, int columns = 1800,
                                  double elevation_jitter_deg = 0, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> jitter(0, elevation_jitter_deg);
  std::vector<LidarPoint> pts;
  for (int col = 0; col < columns; ++col) {
    const double az = col * 2 * M_PI / columns;
    for (std::size_t b = 0; b < elevations_deg.size(); ++b) {
      const double e = (elevations_deg[b] + (elevation_jitter_deg > 0 ? jitter(rng) : 0)) * M_PI / 180;
      const Eigen::Vector3d dir(std::cos(e) * std::cos(az), std::cos(e) * std::sin(az), std::sin(e));
      double t = 1e9;
      if (dir.x() > 1e-9) t = std::min(t, 10.0 / dir.x());
      if (dir.y() > 1e-9) t = std::min(t, 12.0 / dir.y());
      if (dir.x() < -1e-9) t = std::min(t, -20.0 / dir.x());
      if (dir.y() < -1e-9) t = std::min(t, -15.0 / dir.y());
      if (dir.z() < -1e-9) t = std::min(t, -1.7 / dir.z());
      if (dir.z() > 1e-9) t = std::min(t, 6.0 / dir.z());
      const Eigen::Vector3d p = t * dir;
      LidarPoint q;
      q.x = static_cast<float>(p.x());
      q.y = static_cast<float>(p.y());
      q.z = static_cast<float>(p.z());
      q.ring = static_cast<std::int16_t>(b);
      pts.push_back(q);
    }
  }
  return pts;
}

TEST(BeamLayout, LearnsANonUniformLayoutToAHundredthOfADegree) {
  const BeamLayout layout = learn_beam_layout(room_scan(kVlp32c), 1.0, 100.0);
  ASSERT_EQ(layout.elevations_deg.size(), kVlp32c.size());
  for (std::size_t k = 0; k < kVlp32c.size(); ++k)
    EXPECT_NEAR(layout.elevations_deg[k], kVlp32c[k], 0.01) << "beam " << k;
  EXPECT_TRUE(layout.confident);
  EXPECT_GT(layout.clustered_fraction, 0.999);
  // Every return of a 1800-column scan belongs to one beam (none are cropped in this room).
  for (int n : layout.returns) EXPECT_EQ(n, 1800);
  EXPECT_EQ(layout.points_used, 1800 * 32);
}

TEST(BeamLayout, LearnsUniformFansOfManyBeams) {
  for (const auto& fan : {uniform_fan(2.0, -24.8, 64), uniform_fan(22.5, -22.5, 128), uniform_fan(15, -15, 16)}) {
    const BeamLayout layout = learn_beam_layout(room_scan(fan, 1024), 1.0, 100.0);
    ASSERT_EQ(layout.elevations_deg.size(), fan.size());
    EXPECT_TRUE(layout.confident);
    for (std::size_t k = 0; k < fan.size(); ++k) EXPECT_NEAR(layout.elevations_deg[k], fan[k], 0.01);
  }
}

// Elevations blurred to half the beam spacing (as KITTI's HDL-64E, whose lasers sit at
// different heights): no confident layout, so the built-in table stays.
TEST(BeamLayout, BlurredElevationsAreNotConfident) {
  const BeamLayout layout = learn_beam_layout(room_scan(uniform_fan(2.0, -8.33, 32), 1800, 0.12), 1.0, 100.0);
  EXPECT_FALSE(layout.confident);
  EXPECT_LT(layout.clustered_fraction, 0.9);
}

TEST(BeamLayout, KittiRealScansAreNotConfident) {
  for (const char* seq : {"kitti/scans/00", "kitti/scans/05", "kitti/scans/08"}) {
    SCFLOAM_SHARED_DATA_OR_SKIP(dir, seq);
    std::ifstream in(dir / "velodyne" / "000000.bin", std::ios::binary);
    ASSERT_TRUE(in) << dir;
    std::vector<LidarPoint> pts;
    float v[4];
    while (in.read(reinterpret_cast<char*>(v), sizeof v)) {
      LidarPoint p;
      p.x = v[0], p.y = v[1], p.z = v[2];
      pts.push_back(p);
    }
    const BeamLayout layout = learn_beam_layout(pts, 1.0, 200.0);
    EXPECT_GT(layout.points_used, 100000) << seq;
    EXPECT_FALSE(layout.confident) << seq << ": " << layout.clustered_fraction;
  }
}

TEST(BeamLayout, TooFewReturnsLearnNothing) {
  std::vector<LidarPoint> pts = room_scan(kVlp32c, 40);  // 1280 returns
  const BeamLayout layout = learn_beam_layout(pts, 1.0, 100.0);
  EXPECT_EQ(layout.points_used, 1280);
  EXPECT_TRUE(layout.elevations_deg.empty());
  EXPECT_FALSE(layout.confident);
}

TEST(LearnedRingTable, BoundariesHalfwayBetweenBeams) {
  const LearnedRingTable table(kVlp32c);
  ASSERT_EQ(table.beams(), 32);
  for (int k = 0; k < 32; ++k) EXPECT_EQ(table.ring(static_cast<float>(kVlp32c[k])), k);
  // Halfway between -15.639 and -25 is -20.32: just above is beam 30, just below beam 31.
  EXPECT_EQ(table.ring(-20.30f), 30);
  EXPECT_EQ(table.ring(-20.34f), 31);
  // Half a gap of margin beyond the outer beams (top gap 4.667 deg, bottom 9.361 deg).
  EXPECT_EQ(table.ring(17.3f), 0);
  EXPECT_EQ(table.ring(17.4f), -1);
  EXPECT_EQ(table.ring(-29.6f), 31);
  EXPECT_EQ(table.ring(-29.7f), -1);
  EXPECT_EQ(table.ring(std::nanf("")), -1);
  EXPECT_THROW(LearnedRingTable({1.0, 1.0}), Error);
  EXPECT_THROW(LearnedRingTable({-1.0, 1.0}), Error);
  EXPECT_THROW(LearnedRingTable(std::vector<double>{}), Error);
}

BeamLayout layout_of(const std::vector<double>& elevations) {
  return learn_beam_layout(room_scan(elevations, 1024), 1.0, 100.0);
}

TEST(TableFit, EachTableFitsItsOwnSensorAndNotAnother) {
  // HDL-32E's own fan fits its table.
  EXPECT_TRUE(check_table_fit(LidarModel::hdl32, layout_of(uniform_fan(10.67, -30.67, 32))).fits);
  // The VLP-32C's beams 1/3 deg apart fall two or three to one of the HDL-32E's 1.33 deg rings.
  const TableFit vlp32c_in_hdl32 = check_table_fit(LidarModel::hdl32, layout_of(kVlp32c));
  EXPECT_FALSE(vlp32c_in_hdl32.fits);
  EXPECT_GT(vlp32c_in_hdl32.merged_beams, 10);
  // A KITTI-like HDL-64E (+2 .. -24.9 deg): F-LOAM's table ends at -24.33 and drops the two
  // lowest beams; the top beam, exactly at its +2 deg edge, may go too (~5 % of the returns
  // here). No two beams share a ring: it fits.
  std::vector<double> hdl64 = uniform_fan(2.0, 2.0 - 31.0 / 3.0, 32), lower = uniform_fan(-8.87, -24.9, 32);
  hdl64.insert(hdl64.end(), lower.begin(), lower.end());
  const TableFit own = check_table_fit(LidarModel::hdl64, layout_of(hdl64));
  EXPECT_TRUE(own.fits);
  EXPECT_EQ(own.merged_beams, 0);
  EXPECT_GE(own.dropped_beams, 2);
  EXPECT_LE(own.dropped_beams, 3);
  EXPECT_LT(own.dropped_fraction, 0.1);
  // An OS1-128 in the HDL-64E table: 0.35 deg beams in its 0.5 deg lower block merge, and
  // the upper half is outside its field of view.
  const TableFit os128 = check_table_fit(LidarModel::hdl64, layout_of(uniform_fan(22.5, -22.5, 128)));
  EXPECT_FALSE(os128.fits);
  EXPECT_GT(os128.merged_beams, 0);
  EXPECT_GT(os128.dropped_fraction, 0.3);
  // A VLP-16 in the HDL-64E table: its 2 deg beams never share a ring, the seven above +2 deg
  // are cropped: it fits (cropping is reported, not replaced).
  const TableFit vlp16 = check_table_fit(LidarModel::hdl64, layout_of(uniform_fan(15, -15, 16)));
  EXPECT_TRUE(vlp16.fits);
  EXPECT_EQ(vlp16.dropped_beams, 7);
}

// Features from learned rings equal those from the ring field itself.
void extract(const std::string& lidar, bool adopt, const std::vector<LidarPoint>& scan, bool use_ring_field,
             FeatureCloud& edges, FeatureCloud& planes, RingLayoutInfo* info = nullptr) {
  OdometryConfig c;
  c.preprocess.max_range_m = 100;
  c.preprocess.elevation_correction_deg = 0;
  c.rings.lidar = lidar;
  c.rings.adopt_learned_layout = adopt;
  FeatureExtractor extractor(c.preprocess, c.rings, c.features);
  extractor.extract(scan, use_ring_field, edges, planes);
  if (info) *info = extractor.ring_layout();
}

// Edges farther than 0.5 m from the room's four vertical corners: spurious.
int edges_off_the_corners(const FeatureCloud& edges) {
  const Eigen::Vector2f corners[4] = {{10, 12}, {-20, 12}, {-20, -15}, {10, -15}};
  int off = 0;
  for (const auto& e : edges) {
    float best = 1e9f;
    for (const auto& k : corners) best = std::min(best, (e.head<2>() - k).norm());
    // Floor and ceiling meet the walls in horizontal lines: edges there are real too.
    const bool on_horizontal_edge = std::abs(e.z() + 1.7f) < 0.3f || std::abs(e.z() - 6.0f) < 0.3f;
    off += best > 0.5f && !on_horizontal_edge;
  }
  return off;
}

TEST(FeatureExtractorLayout, AutoRingsGiveTheRingFieldsFeatures) {
  const auto scan = room_scan(kVlp32c);
  FeatureCloud e_field, p_field, e_auto, p_auto;
  RingLayoutInfo info;
  extract("auto", true, scan, true, e_field, p_field, &info);
  EXPECT_EQ(info.source, "ring field");
  extract("auto", true, scan, false, e_auto, p_auto, &info);
  EXPECT_EQ(info.source, "learned");
  EXPECT_EQ(info.beams, 32);
  EXPECT_NEAR(info.highest_deg, 15.0, 0.01);
  EXPECT_NEAR(info.lowest_deg, -25.0, 0.01);
  ASSERT_FALSE(e_field.empty());
  ASSERT_EQ(e_auto.size(), e_field.size());
  ASSERT_EQ(p_auto.size(), p_field.size());
  for (std::size_t i = 0; i < e_auto.size(); ++i) EXPECT_EQ(e_auto[i], e_field[i]) << i;
  for (std::size_t i = 0; i < p_auto.size(); i += 13) EXPECT_EQ(p_auto[i], p_field[i]) << i;
}

// The HDL-32E table on a VLP-32C in firing order interleaves two or three beams per ring: the
// zigzag between them is curvature all along the walls, which raises each ring's noise
// threshold (features.edge_noise_factor x the median) above the room's corners, and the edges
// are lost. Adopting the learned beams gives the ring field's features back.
TEST(FeatureExtractorLayout, ATableThatDoesNotFitIsReplacedByTheLearnedBeams) {
  const auto scan = room_scan(kVlp32c);
  FeatureCloud e_field, p_field, e_table, p_table, e_adopted, p_adopted;
  RingLayoutInfo info;
  extract("hdl32", true, scan, true, e_field, p_field);
  extract("hdl32", false, scan, false, e_table, p_table, &info);
  EXPECT_EQ(info.source, "table");
  extract("hdl32", true, scan, false, e_adopted, p_adopted, &info);
  EXPECT_EQ(info.source, "learned");
  EXPECT_NE(info.reason.find("hdl32 ring table does not fit"), std::string::npos) << info.reason;
  ASSERT_GT(e_field.size(), 50u);
  EXPECT_EQ(edges_off_the_corners(e_field), 0);
  EXPECT_LT(e_table.size(), e_field.size() / 4);
  EXPECT_EQ(edges_off_the_corners(e_adopted), 0);
  EXPECT_EQ(e_adopted.size(), e_field.size());
  EXPECT_EQ(p_adopted.size(), p_field.size());
}

// A 32-beam driver's ring field under a 16-beam preset: all 32 rings are used, as under a
// 128-beam one (before, rings 16-31 were dropped).
TEST(FeatureExtractorLayout, RingFieldBeyondThePresetsBeamsIsKept) {
  const auto scan = room_scan(kVlp32c);
  FeatureCloud e16, p16, e128, p128;
  RingLayoutInfo info;
  extract("vlp16", true, scan, true, e16, p16, &info);
  EXPECT_EQ(info.source, "ring field");
  EXPECT_EQ(info.beams, 32);
  extract("os1-128", true, scan, true, e128, p128);
  ASSERT_FALSE(e128.empty());
  EXPECT_EQ(e16, e128);
  EXPECT_EQ(p16, p128);
}

TEST(FeatureExtractorLayout, ATableThatFitsStays) {
  FeatureCloud e, p;
  RingLayoutInfo info;
  extract("vlp16", true, room_scan(uniform_fan(15, -15, 16)), false, e, p, &info);
  EXPECT_EQ(info.source, "table");
  EXPECT_EQ(info.beams, 16);
  EXPECT_FALSE(e.empty());
}

TEST(FeatureExtractorLayout, AutoOnBlurredElevationsSaysWhatToDo) {
  FeatureCloud e, p;
  try {
    extract("auto", true, room_scan(uniform_fan(2.0, -8.33, 32), 1800, 0.12), false, e, p);
    FAIL() << "expected an error";
  } catch (const Error& err) {
    EXPECT_NE(std::string(err.what()).find("set rings.lidar"), std::string::npos) << err.what();
  }
}

// A first scan too sparse to learn from gives no features; the next full scan decides.
TEST(FeatureExtractorLayout, AutoWaitsForAScanWithEnoughReturns) {
  OdometryConfig c;
  c.preprocess.max_range_m = 100;
  c.preprocess.elevation_correction_deg = 0;
  c.rings.lidar = "auto";
  FeatureExtractor extractor(c.preprocess, c.rings, c.features);
  FeatureCloud e, p;
  extractor.extract(room_scan(kVlp32c, 40), false, e, p);
  EXPECT_TRUE(e.empty());
  EXPECT_TRUE(p.empty());
  EXPECT_EQ(extractor.ring_layout().source, "none");
  extractor.extract(room_scan(kVlp32c), false, e, p);
  EXPECT_EQ(extractor.ring_layout().source, "learned");
  EXPECT_EQ(extractor.ring_layout().beams, 32);
  EXPECT_FALSE(e.empty());
  EXPECT_FALSE(p.empty());
}

}  // namespace
}  // namespace scfloam
