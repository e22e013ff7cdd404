// Bags written here (ROS 1 through librosbag's writer, ROS 2 MCAP and sqlite3 through the test
// writers) carrying simulated-like scans, read back through open_bag_source / inspect_bag.
#include <gtest/gtest.h>

#include <thread>

#include "scfloam/error.hpp"
#include "scfloam/io/bag_source.hpp"
#include "test_bag_writers.hpp"
#include "test_paths.hpp"

namespace scfloam {
namespace {

// A ring-structured scan: 16 beams x 90 azimuths on a 10 m cylinder, per-point time over 0.1 s.
std::vector<LidarPoint> ring_scan(int frame) {
  std::vector<LidarPoint> pts;
  for (int ring = 0; ring < 16; ++ring)
    for (int a = 0; a < 90; ++a) {
      const double az = a * 2 * M_PI / 90, el = (-15 + 2 * ring) * M_PI / 180;
      LidarPoint p;
      p.x = static_cast<float>(10 * std::cos(az) + 0.1 * frame);
      p.y = static_cast<float>(10 * std::sin(az));
      p.z = static_cast<float>(10 * std::tan(el));
      p.intensity = static_cast<float>((ring * 7 + a) % 256);
      p.ring = static_cast<std::int16_t>(ring);
      p.time_s = static_cast<float>(0.1 * a / 90);
      pts.push_back(p);
    }
  return pts;
}

void expect_scan(const Scan& s, const std::vector<LidarPoint>& pts, double stamp) {
  EXPECT_NEAR(s.timestamp_s, stamp, 1e-9);
  ASSERT_EQ(s.points.size(), pts.size());
  EXPECT_TRUE(s.has_ring);
  EXPECT_TRUE(s.has_time);
  for (std::size_t i = 0; i < pts.size(); i += 37) {
    EXPECT_FLOAT_EQ(s.points[i].x, pts[i].x);
    EXPECT_FLOAT_EQ(s.points[i].z, pts[i].z);
    EXPECT_FLOAT_EQ(s.points[i].intensity, pts[i].intensity);
    EXPECT_EQ(s.points[i].ring, pts[i].ring);
    EXPECT_NEAR(s.points[i].time_s, pts[i].time_s, 1e-7);
  }
}

constexpr int kFrames = 5;
double stamp_of(int i) { return 1700000000.0 + 0.1 * i + 0.000123; }

void write_ros1_bag(const std::filesystem::path& path, const std::vector<std::string>& topics) {
  std::vector<test::OwnedCloud> clouds;
  for (int i = 0; i < kFrames; ++i) clouds.push_back(test::make_cloud(ring_scan(i), stamp_of(i), {}));
  test::write_ros1_bag(path, topics, clouds);
}

TEST(BagRoundTrip, Ros1ThroughLibrosbagWriter) {
  const auto dir = test::scratch_dir("bag_ros1");
  const auto path = dir / "scans.bag";
  write_ros1_bag(path, {"/velodyne_points", "/other_points"});
  ASSERT_TRUE(is_bag_input(path));
  // Two PointCloud2 topics: the error lists them; --topic picks one.
  try {
    open_bag_source(path, {});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/other_points, /velodyne_points"), std::string::npos) << e.what();
  }
  ScanSourceOptions opt;
  opt.topic = "/velodyne_points";
  const auto source = open_bag_source(path, opt);
  ASSERT_EQ(source->size(), static_cast<std::size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) expect_scan(source->load(i), ring_scan(i), stamp_of(i));
  const InputInfo info = inspect_bag(path, opt);
  EXPECT_EQ(info.scans, static_cast<std::size_t>(kFrames));
  EXPECT_EQ(info.points_in_first_scan, 16u * 90u);
  EXPECT_NEAR(info.end_time_s - info.start_time_s, 0.1 * (kFrames - 1), 1e-6);
  opt.topic = "/missing";
  EXPECT_THROW(open_bag_source(path, opt), Error);
}

std::vector<std::uint8_t> cloud_bytes(int i, bool big_endian = false) {
  return test::encode_cdr(test::make_cloud(ring_scan(i), stamp_of(i), {}), big_endian);
}

TEST(BagRoundTrip, McapEveryChunkingCompressionAndSummary) {
  const auto dir = test::scratch_dir("bag_mcap");
  int variant = 0;
  for (const char* compression : {"", "zstd", "lz4"})
    for (bool chunked : {false, true})
      for (bool summary : {false, true}) {
        if (!chunked && std::string(compression) != "") continue;
        test::McapTestWriter w(compression, chunked, summary);
        const auto imu = w.add_topic("/imu", "sensor_msgs/msg/Imu");
        const auto lidar = w.add_topic("/points", "sensor_msgs/msg/PointCloud2");
        for (int i = 0; i < kFrames; ++i) {
          // Written out of time order; the reader orders by log time.
          const int k = (i * 3) % kFrames;
          w.write(lidar, static_cast<std::uint64_t>(stamp_of(k) * 1e9), cloud_bytes(k, k % 2 == 1));
          w.write(imu, static_cast<std::uint64_t>(stamp_of(k) * 1e9) + 1, {0, 1, 0, 0});
        }
        const auto path = dir / ("v" + std::to_string(variant++) + ".mcap");
        test::write_bytes(path, w.finish());
        const auto source = open_bag_source(path, {});
        ASSERT_EQ(source->size(), static_cast<std::size_t>(kFrames)) << path;
        for (int i = 0; i < kFrames; ++i) expect_scan(source->load(i), ring_scan(i), stamp_of(i));
        const InputInfo info = inspect_bag(path, {});
        EXPECT_EQ(info.kind, "ROS 2 bag (MCAP)");
        EXPECT_EQ(info.topics.size(), 2u);
      }
  EXPECT_EQ(variant, 8);
}

TEST(BagRoundTrip, SqliteOldAndNewSchemaSplitAndWrongFormat) {
  const auto dir = test::scratch_dir("bag_sqlite");
  std::vector<std::pair<std::int64_t, std::vector<std::uint8_t>>> first, second;
  for (int i = 0; i < kFrames; ++i)
    (i < 3 ? first : second).push_back({static_cast<std::int64_t>(stamp_of(i) * 1e9), cloud_bytes(i)});
  test::write_sqlite_bag(dir / "split_0.db3", "/points", "cdr", first, true);
  test::write_sqlite_bag(dir / "split_1.db3", "/points", "cdr", second, false);
  std::ofstream(dir / "metadata.yaml")
      << "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n"
         "  relative_file_paths:\n    - split_0.db3\n    - split_1\n  compression_format: \"\"\n";
  ASSERT_TRUE(is_bag_input(dir));
  const auto source = open_bag_source(dir, {});
  ASSERT_EQ(source->size(), static_cast<std::size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) expect_scan(source->load(i), ring_scan(i), stamp_of(i));
  const InputInfo info = inspect_bag(dir, {});
  EXPECT_EQ(info.kind, "ROS 2 bag (sqlite3)");
  ASSERT_EQ(info.topics.size(), 2u);
  EXPECT_EQ(info.topics[1].messages, static_cast<std::size_t>(kFrames));

  test::write_sqlite_bag(dir / "wrong.db3", "/points", "wrong_format", first, true);
  try {
    open_bag_source(dir / "wrong.db3", {});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("serialization format 'wrong_format'"), std::string::npos) << e.what();
  }
}

TEST(BagRoundTrip, ConcurrentLoadsOfDistinctIndices) {
  const auto dir = test::scratch_dir("bag_threads");
  test::McapTestWriter w("zstd", true, true, 1);
  const auto lidar = w.add_topic("/points", "sensor_msgs/msg/PointCloud2");
  for (int i = 0; i < kFrames; ++i) w.write(lidar, static_cast<std::uint64_t>(stamp_of(i) * 1e9), cloud_bytes(i));
  test::write_bytes(dir / "t.mcap", w.finish());
  std::vector<std::pair<std::int64_t, std::vector<std::uint8_t>>> msgs;
  for (int i = 0; i < kFrames; ++i) msgs.push_back({static_cast<std::int64_t>(stamp_of(i) * 1e9), cloud_bytes(i)});
  test::write_sqlite_bag(dir / "t.db3", "/points", "cdr", msgs, true);
  write_ros1_bag(dir / "t.bag", {"/points"});
  for (const char* name : {"t.mcap", "t.db3", "t.bag"}) {
    const auto source = open_bag_source(dir / name, {});
    std::vector<Scan> scans(kFrames);
    std::vector<std::thread> threads;
    for (int rep = 0; rep < 20; ++rep) {
      threads.clear();
      for (int i = 0; i < kFrames; ++i) threads.emplace_back([&, i] { scans[i] = source->load(i); });
      for (auto& t : threads) t.join();
      for (int i = 0; i < kFrames; ++i) ASSERT_NEAR(scans[i].timestamp_s, stamp_of(i), 1e-9);
    }
  }
}

}  // namespace
}  // namespace scfloam
