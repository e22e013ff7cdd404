// Truncated and corrupted bags of every kind: an Error naming the file, never a crash.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "scfloam/error.hpp"
#include "scfloam/io/bag_source.hpp"
#include "test_bag_writers.hpp"
#include "test_paths.hpp"

namespace scfloam {
namespace {

std::vector<char> slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Opens, inspects and loads every scan; returns false when an Error was thrown. Any other
// exception or a crash fails the test.
bool read_all(const std::filesystem::path& path) {
  try {
    inspect_bag(path, {});
    const auto source = open_bag_source(path, {});
    for (std::size_t i = 0; i < source->size(); ++i) source->load(i);
    return true;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path.filename().string()), std::string::npos) << e.what();
    return false;
  }
}

void damage(const std::filesystem::path& original, const std::string& tag) {
  const std::vector<char> bytes = slurp(original);
  ASSERT_FALSE(bytes.empty());
  const auto dir = test::scratch_dir("bag_corrupt_" + tag);
  const auto path = dir / original.filename();
  int errors = 0, cases = 0;
  // Truncations at 12 places, then byte flips in 40 places.
  for (int k = 0; k < 12; ++k) {
    const std::size_t n = bytes.size() * static_cast<std::size_t>(k) / 12;
    std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(n));
    errors += !read_all(path);
    ++cases;
  }
  for (int k = 0; k < 40; ++k) {
    std::vector<char> copy = bytes;
    const std::size_t at = (bytes.size() * static_cast<std::size_t>(k * 7919 % 40)) / 40;
    for (std::size_t j = at; j < std::min(copy.size(), at + 8); ++j) copy[j] = static_cast<char>(copy[j] ^ 0x5A);
    std::ofstream(path, std::ios::binary).write(copy.data(), static_cast<std::streamsize>(copy.size()));
    read_all(path);
    ++cases;
  }
  EXPECT_GE(errors, 11) << tag << ": truncated files must not read as complete bags";
}

TEST(BagCorrupt, Ros1) {
  SCFLOAM_SHARED_DATA_OR_SKIP(p, "bags/cdcpd/rope_example_10_points_2020-02-20-16-58-46.bag");
  damage(p, "ros1");
}

TEST(BagCorrupt, Mcap) {
  SCFLOAM_SHARED_DATA_OR_SKIP(p, "bags/rosbags-rs/tests/test_bags/test_bag_mcap/test_bag_mcap.mcap");
  damage(p, "mcap");
}

TEST(BagCorrupt, Sqlite) {
  SCFLOAM_SHARED_DATA_OR_SKIP(p, "bags/rosbags-rs/tests/test_bags/test_bag_sqlite3/test_bag_sqlite3.db3");
  damage(p, "sqlite");
}

// Bags written here, whose messages sit in compressed chunks: damage reaches lz4 / zstd data.
std::vector<test::OwnedCloud> small_clouds() {
  std::vector<test::OwnedCloud> clouds;
  for (int k = 0; k < 6; ++k) {
    std::vector<LidarPoint> pts(200);
    for (std::size_t i = 0; i < pts.size(); ++i) pts[i].x = static_cast<float>(i + k);
    clouds.push_back(test::make_cloud(pts, 100.0 + k, {}));
  }
  return clouds;
}

TEST(BagCorrupt, Ros1Lz4Chunks) {
  const auto dir = test::scratch_dir("bag_corrupt_src_ros1");
  test::write_ros1_bag(dir / "lz4.bag", {"/points"}, small_clouds());
  damage(dir / "lz4.bag", "ros1_lz4");
}

TEST(BagCorrupt, McapZstdAndLz4Chunks) {
  const auto dir = test::scratch_dir("bag_corrupt_src_mcap");
  for (const char* compression : {"zstd", "lz4"}) {
    test::McapTestWriter w(compression, true, true, 2);
    const auto ch = w.add_topic("/points", "sensor_msgs/msg/PointCloud2");
    for (const auto& c : small_clouds())
      w.write(ch, static_cast<std::uint64_t>(c.meta.stamp_sec) * 1000000000ULL, test::encode_cdr(c, false));
    const auto path = dir / (std::string(compression) + ".mcap");
    test::write_bytes(path, w.finish());
    damage(path, std::string("mcap_") + compression);
  }
}

TEST(BagCorrupt, NotABag) {
  const auto dir = test::scratch_dir("bag_not");
  std::ofstream(dir / "x.bag") << "hello";
  EXPECT_THROW(open_bag_source(dir / "x.bag", {}), Error);
  std::ofstream(dir / "x.mcap") << "hello";
  EXPECT_THROW(open_bag_source(dir / "x.mcap", {}), Error);
  std::ofstream(dir / "x.db3") << "hello world, not sqlite";
  EXPECT_THROW(open_bag_source(dir / "x.db3", {}), Error);
  EXPECT_THROW(open_bag_source(dir / "missing.bag", {}), Error);
  std::filesystem::create_directories(dir / "b");
  std::ofstream(dir / "b" / "metadata.yaml") << "rosbag2_bagfile_information: [\n";
  EXPECT_THROW(open_bag_source(dir / "b", {}), Error);
}

}  // namespace
}  // namespace scfloam
