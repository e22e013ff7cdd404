// PointCloud2 -> Scan over unusual layouts, through the CDR encoder of the test writers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "scfloam/error.hpp"
#include "scfloam/io/pointcloud2.hpp"
#include "test_bag_writers.hpp"

namespace scfloam {
namespace {

std::vector<LidarPoint> sample_points(int n) {
  std::vector<LidarPoint> pts;
  for (int i = 0; i < n; ++i) {
    LidarPoint p;
    p.x = 1.25f * i - 7.5f;
    p.y = 0.5f * i + 0.125f;
    p.z = -1.0f + 0.0625f * i;
    p.intensity = static_cast<float>(i % 200);
    p.ring = static_cast<std::int16_t>(i % 64);
    p.time_s = 0.1f * static_cast<float>(i) / static_cast<float>(n);
    pts.push_back(p);
  }
  return pts;
}

Scan round_trip(const std::vector<LidarPoint>& pts, double stamp, const test::CloudLayout& layout,
                bool cdr_big_endian) {
  const test::OwnedCloud c = test::make_cloud(pts, stamp, layout);
  const std::vector<std::uint8_t> bytes = test::encode_cdr(c, cdr_big_endian);
  const PointCloud2View v = decode_cdr_pointcloud2(bytes.data(), bytes.size(), "test");
  EXPECT_EQ(v.height, c.meta.height);
  EXPECT_EQ(v.width, c.meta.width);
  EXPECT_EQ(v.point_step, c.meta.point_step);
  EXPECT_EQ(v.fields.size(), c.meta.fields.size());
  EXPECT_EQ(v.frame_id, "velodyne");
  return pointcloud2_to_scan(v, "test");
}

void expect_points(const Scan& s, const std::vector<LidarPoint>& pts, const test::CloudLayout& L,
                   double time_tol) {
  ASSERT_EQ(s.points.size(), pts.size());
  EXPECT_EQ(s.has_ring, L.ring);
  EXPECT_EQ(s.has_time, L.time != test::TimeField::None);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_FLOAT_EQ(s.points[i].x, pts[i].x);
    EXPECT_FLOAT_EQ(s.points[i].y, pts[i].y);
    EXPECT_FLOAT_EQ(s.points[i].z, pts[i].z);
    EXPECT_FLOAT_EQ(s.points[i].intensity, L.intensity ? pts[i].intensity : 0.f);
    EXPECT_EQ(s.points[i].ring, L.ring ? pts[i].ring : -1);
    if (L.time != test::TimeField::None) {
      EXPECT_NEAR(s.points[i].time_s, pts[i].time_s, time_tol);
    }
  }
}

TEST(PointCloud2, DefaultLayoutBothCdrByteOrders) {
  const auto pts = sample_points(100);
  test::CloudLayout L;
  for (bool be : {false, true}) {
    const Scan s = round_trip(pts, 1234.5, L, be);
    EXPECT_DOUBLE_EQ(s.timestamp_s, 1234.5);
    expect_points(s, pts, L, 1e-7);
  }
}

TEST(PointCloud2, Float64XyzPaddingBigPointStepBigEndianData) {
  const auto pts = sample_points(50);
  test::CloudLayout L;
  L.xyz_type = 8;
  L.padding = 37;  // odd: fields of the next point are unaligned
  L.big_endian = true;
  expect_points(round_trip(pts, 10.0, L, false), pts, L, 1e-7);
  L.padding = 4000;
  expect_points(round_trip(pts, 10.0, L, true), pts, L, 1e-7);
}

TEST(PointCloud2, MissingIntensityRingAndTime) {
  const auto pts = sample_points(20);
  test::CloudLayout L;
  L.intensity = false;
  L.ring = false;
  L.time = test::TimeField::None;
  const Scan s = round_trip(pts, 3.0, L, false);
  expect_points(s, pts, L, 0);
  EXPECT_FALSE(s.has_ring);
  EXPECT_FALSE(s.has_time);
}

TEST(PointCloud2, OrganizedCloudDropsNaNs) {
  const auto pts = sample_points(61);  // 4 rows of 16: 3 NaN slots at the end
  test::CloudLayout L;
  L.height = 4;
  const test::OwnedCloud c = test::make_cloud(pts, 0.0, L);
  ASSERT_EQ(c.meta.width * c.meta.height, 64u);
  expect_points(round_trip(pts, 0.0, L, false), pts, L, 1e-7);
}

// Rows longer than the conversion's blocks of 256 points, in big-endian float64, each row a
// run of its own (row_step), with the NaN slots of the last row dropped.
TEST(PointCloud2, OrganizedRowsLongerThanTheConversionsBlocks) {
  const auto pts = sample_points(1000);  // 3 rows of 334: 2 NaN slots at the end
  test::CloudLayout L;
  L.height = 3;
  L.xyz_type = 8;
  L.big_endian = true;
  L.padding = 3;
  expect_points(round_trip(pts, 5.0, L, true), pts, L, 1e-7);
}

TEST(PointCloud2, TimeFieldConventions) {
  const auto pts = sample_points(30);
  test::CloudLayout L;
  L.time = test::TimeField::RelativeNanosU32;  // Ouster `t`
  expect_points(round_trip(pts, 1.6e9 + 0.25, L, false), pts, L, 1e-8);
  // Absolute float64 seconds (Hesai): relative after subtracting the stamp (float64 keeps
  // ~0.2 us at 1.6e9 s).
  L.time = test::TimeField::AbsoluteSecondsF64;
  expect_points(round_trip(pts, 1.6e9 + 0.25, L, false), pts, L, 1e-6);
  // Absolute float64 nanoseconds (livox_ros_driver2): 1.6e18 ns holds ~0.3 us.
  L.time = test::TimeField::AbsoluteNanosF64;
  expect_points(round_trip(pts, 1.6e9 + 0.25, L, false), pts, L, 1e-6);
  // Relative seconds on a small simulated stamp stay relative.
  L.time = test::TimeField::RelativeSecondsF32;
  expect_points(round_trip(pts, 0.05, L, false), pts, L, 1e-7);
  // Absolute seconds that are 100 s away from the stamp are not understood: no time.
  L.time = test::TimeField::AbsoluteSecondsF64;
  test::OwnedCloud c = test::make_cloud(pts, 1.6e9, L);
  c.meta.stamp_sec += 100;
  const auto bytes = test::encode_cdr(c, false);
  const Scan s = pointcloud2_to_scan(decode_cdr_pointcloud2(bytes.data(), bytes.size(), "w"), "w");
  EXPECT_FALSE(s.has_time);
  for (const LidarPoint& p : s.points) EXPECT_EQ(p.time_s, 0.f);
}

TEST(PointCloud2, AbsoluteTimesWithoutAStampReadAsPcdDoes) {
  // A header stamp of 0 (some converters leave it unset) with absolute float64 seconds: as in
  // a PCD file, the earliest point stands for the stamp, and the scan takes its time.
  const auto pts = sample_points(30);  // times 0 .. 0.097 s
  test::CloudLayout L;
  L.time = test::TimeField::AbsoluteSecondsF64;
  test::OwnedCloud c = test::make_cloud(pts, 1.6e9 + 0.25, L);
  c.meta.stamp_sec = 0;
  c.meta.stamp_nanosec = 0;
  const auto bytes = test::encode_cdr(c, false);
  const Scan s = pointcloud2_to_scan(decode_cdr_pointcloud2(bytes.data(), bytes.size(), "w"), "w");
  EXPECT_NEAR(s.timestamp_s, 1.6e9 + 0.25, 1e-6);
  expect_points(s, pts, L, 1e-6);
}

TEST(PointCloud2, BadCloudsAreErrors) {
  const auto pts = sample_points(10);
  test::OwnedCloud c = test::make_cloud(pts, 0.0, {});
  c.data.resize(c.data.size() - 1);  // short data
  auto bytes = test::encode_cdr(c, false);
  PointCloud2View v = decode_cdr_pointcloud2(bytes.data(), bytes.size(), "bag.db3: topic /p message 3");
  try {
    pointcloud2_to_scan(v, "bag.db3: topic /p message 3");
    FAIL() << "short data accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bag.db3: topic /p message 3"), std::string::npos) << e.what();
  }
  c = test::make_cloud(pts, 0.0, {});
  c.meta.fields[3].offset = c.meta.point_step - 2;  // intensity runs past the point
  bytes = test::encode_cdr(c, false);
  v = decode_cdr_pointcloud2(bytes.data(), bytes.size(), "w");
  EXPECT_THROW(pointcloud2_to_scan(v, "w"), Error);
  c = test::make_cloud(pts, 0.0, {});
  c.meta.fields[2].name = "elevation";  // no z
  bytes = test::encode_cdr(c, false);
  v = decode_cdr_pointcloud2(bytes.data(), bytes.size(), "w");
  EXPECT_THROW(pointcloud2_to_scan(v, "w"), Error);
  // Every truncation of the message is an Error, never a read past the buffer.
  c = test::make_cloud(pts, 0.0, {});
  bytes = test::encode_cdr(c, true);
  for (std::size_t n = 0; n + 1 < bytes.size(); ++n) {
    std::vector<std::uint8_t> cut(bytes.begin(), bytes.begin() + static_cast<long>(n));
    try {
      const PointCloud2View cv = decode_cdr_pointcloud2(cut.data(), cut.size(), "w");
      pointcloud2_to_scan(cv, "w");
      // Only the trailing is_dense byte may be missing.
      EXPECT_EQ(n, bytes.size() - 1);
    } catch (const Error&) {
    }
  }
}

// Values a corrupt or unusual cloud may carry: a float ring field with NaN or beyond int16,
// an infinite intensity. The points keep their coordinates; the ring becomes "no ring" (-1) or
// the nearest valid value, the intensity 0 (as the PCD and PLY readers do), never an
// undefined cast.
TEST(PointCloud2, OutOfRangeRingAndIntensityValuesAreClampedNotCast) {
  const auto pts = sample_points(4);
  test::OwnedCloud c = test::make_cloud(pts, 0.0, {});
  ASSERT_EQ(c.meta.fields[3].name, "intensity");
  ASSERT_EQ(c.meta.fields[4].name, "ring");
  // The float32 "intensity" slot read as the ring field; the uint16 ring slot ignored.
  c.meta.fields[3].name = "ring";
  c.meta.fields[4].name = "unused";
  const float rings[] = {std::nanf(""), 1e9f, -5.f, 7.f};
  for (std::size_t i = 0; i < 4; ++i)
    std::memcpy(c.data.data() + i * c.meta.point_step + c.meta.fields[3].offset, &rings[i], 4);
  auto bytes = test::encode_cdr(c, false);
  Scan s = pointcloud2_to_scan(decode_cdr_pointcloud2(bytes.data(), bytes.size(), "w"), "w");
  ASSERT_EQ(s.points.size(), 4u);
  EXPECT_TRUE(s.has_ring);
  EXPECT_EQ(s.points[0].ring, -1);
  EXPECT_EQ(s.points[1].ring, 32767);
  EXPECT_EQ(s.points[2].ring, -1);
  EXPECT_EQ(s.points[3].ring, 7);
  EXPECT_FLOAT_EQ(s.points[1].x, pts[1].x);
  // An infinite intensity reads as 0.
  c = test::make_cloud(pts, 0.0, {});
  const float inf = std::numeric_limits<float>::infinity();
  std::memcpy(c.data.data() + 2 * c.meta.point_step + c.meta.fields[3].offset, &inf, 4);
  bytes = test::encode_cdr(c, false);
  s = pointcloud2_to_scan(decode_cdr_pointcloud2(bytes.data(), bytes.size(), "w"), "w");
  ASSERT_EQ(s.points.size(), 4u);
  EXPECT_EQ(s.points[2].intensity, 0.f);
  EXPECT_EQ(s.points[1].intensity, pts[1].intensity);
}

// The same field names as the PCD and PLY readers (field_names.hpp): `reflectance` is the intensity.
TEST(PointCloud2, ReflectanceIsTheIntensityAsInPcd) {
  const auto pts = sample_points(5);
  test::OwnedCloud c = test::make_cloud(pts, 0.0, {});
  ASSERT_EQ(c.meta.fields[3].name, "intensity");
  c.meta.fields[3].name = "reflectance";
  const auto bytes = test::encode_cdr(c, false);
  const Scan s = pointcloud2_to_scan(decode_cdr_pointcloud2(bytes.data(), bytes.size(), "w"), "w");
  ASSERT_EQ(s.points.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(s.points[i].intensity, pts[i].intensity) << i;
}

TEST(PointCloud2, DescribeFields) {
  const test::OwnedCloud c = test::make_cloud(sample_points(3), 0.0, {});
  const auto f = describe_point_fields(c.meta.fields);
  const std::vector<std::string> want = {"x:float32", "y:float32", "z:float32",
                                         "intensity:float32", "ring:uint16", "time:float32"};
  EXPECT_EQ(f, want);
}

}  // namespace
}  // namespace scfloam
