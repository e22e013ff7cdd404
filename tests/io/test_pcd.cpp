// PCD: round trips of the three encodings, unusual layouts written by hand, files written by
// another library (Open3D), and truncated/corrupt files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>
#include <random>
#include <sys/stat.h>
#include <thread>

#include "scfloam/error.hpp"
#include "scfloam/io/lzf.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using namespace scfloam;

namespace {

std::vector<LidarPoint> sample_points(std::size_t n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-50, 50);
  std::vector<LidarPoint> pts(n);
  for (std::size_t i = 0; i < n; ++i) {
    pts[i].x = u(rng);
    pts[i].y = u(rng);
    pts[i].z = u(rng) / 10;
    pts[i].intensity = static_cast<float>(i % 256);
    pts[i].ring = static_cast<std::int16_t>(i % 64);
    pts[i].time_s = 0.1f * static_cast<float>(i) / static_cast<float>(n);
  }
  return pts;
}

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

// The header of an unorganized binary PCD of `points` points; the points' bytes follow.
std::string binary_header(const std::string& fields, const std::string& sizes, const std::string& types,
                          int points) {
  const std::string n = std::to_string(points);
  return "VERSION 0.7\nFIELDS " + fields + "\nSIZE " + sizes + "\nTYPE " + types + "\nWIDTH " + n +
         "\nHEIGHT 1\nPOINTS " + n + "\nDATA binary\n";
}

template <typename T>
void append(std::string& s, T v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof v);
}

std::string error_of(const fs::path& path) {
  try {
    read_pcd(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Lzf, RoundTripOfRepetitiveAndRandomData) {
  std::vector<unsigned char> data(100000);
  std::mt19937 rng(3);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = i < 50000 ? static_cast<unsigned char>(i % 7) : rng() & 0xff;
  const auto packed = lzf_compress(data.data(), data.size());
  EXPECT_LT(packed.size(), data.size() * 6 / 10);  // the repetitive half compresses
  const auto back = lzf_decompress(packed.data(), packed.size(), data.size());
  ASSERT_TRUE(back);
  EXPECT_EQ(*back, data);
  EXPECT_FALSE(lzf_decompress(packed.data(), packed.size(), data.size() + 1));  // wrong size
  std::vector<unsigned char> bad = {0xe0, 0x10, 0xff};  // reference before the start
  EXPECT_FALSE(lzf_decompress(bad.data(), bad.size(), 20));
  EXPECT_FALSE(lzf_decompress(packed.data(), packed.size() - 1, data.size()));  // truncated
}

TEST(Lzf, IncompressibleRunsAndEmptyInputsRoundTrip) {
  std::vector<unsigned char> noise(1 << 20);
  std::mt19937 rng(5);
  for (auto& b : noise) b = rng() & 0xff;
  const auto packed_noise = lzf_compress(noise.data(), noise.size());  // grows, must still fit
  const auto noise_back = lzf_decompress(packed_noise.data(), packed_noise.size(), noise.size());
  ASSERT_TRUE(noise_back);
  EXPECT_EQ(*noise_back, noise);

  const std::vector<unsigned char> zeros(1 << 20, 0);
  const auto packed_zeros = lzf_compress(zeros.data(), zeros.size());
  EXPECT_LT(packed_zeros.size(), zeros.size() / 50);
  const auto zeros_back = lzf_decompress(packed_zeros.data(), packed_zeros.size(), zeros.size());
  ASSERT_TRUE(zeros_back);
  EXPECT_EQ(*zeros_back, zeros);
  // A size no LZF stream of this length can reach (over 88 bytes out per byte in) is refused
  // before anything that large is allocated.
  EXPECT_FALSE(lzf_decompress(packed_zeros.data(), 10, std::size_t{1} << 31));

  EXPECT_TRUE(lzf_compress(nullptr, 0).empty());
  const auto empty = lzf_decompress(nullptr, 0, 0);
  ASSERT_TRUE(empty);
  EXPECT_TRUE(empty->empty());
}

TEST(Pcd, RoundTripOfEveryEncodingWithAndWithoutRingAndTime) {
  const fs::path dir = test::scratch_dir("pcd_round_trip");
  const auto pts = sample_points(5000);
  for (auto enc : {PcdEncoding::kAscii, PcdEncoding::kBinary, PcdEncoding::kBinaryCompressed}) {
    for (bool ring_time : {false, true}) {
      const fs::path path = dir / ("c" + std::to_string(int(enc)) + (ring_time ? "rt" : "") + ".pcd");
      write_pcd(path, pts, enc, ring_time);
      const PointCloudFile f = read_pcd(path);
      ASSERT_EQ(f.scan.points.size(), pts.size()) << path;
      EXPECT_EQ(f.scan.has_ring, ring_time);
      EXPECT_EQ(f.scan.has_time, ring_time);
      for (std::size_t i = 0; i < pts.size(); ++i) {
        const auto& a = pts[i];
        const auto& b = f.scan.points[i];
        ASSERT_EQ(a.x, b.x) << i;  // ascii is written with 9 digits: float32 exact
        ASSERT_EQ(a.y, b.y);
        ASSERT_EQ(a.z, b.z);
        ASSERT_EQ(a.intensity, b.intensity);
        if (ring_time) {
          ASSERT_EQ(a.ring, b.ring);
          ASSERT_EQ(a.time_s, b.time_s);
        }
      }
    }
  }
}

// A scan read through a pipe (no size to ask for) reads the same as from a file: the reader
// takes the whole file in one read when it can and falls back to a stream when it cannot.
TEST(Pcd, ReadsThroughAPipeAsFromAFile) {
  const fs::path dir = test::scratch_dir("pcd_pipe");
  const auto pts = sample_points(3000);
  const fs::path file = dir / "scan.pcd", pipe = dir / "pipe.pcd";
  write_pcd(file, pts, PcdEncoding::kBinary, true);
  fs::remove(pipe);
  ASSERT_EQ(mkfifo(pipe.c_str(), 0600), 0) << std::strerror(errno);
  std::thread writer([&] {
    std::ifstream in(file, std::ios::binary);
    std::ofstream out(pipe, std::ios::binary);
    out << in.rdbuf();
  });
  const PointCloudFile through_pipe = read_pcd(pipe);
  writer.join();
  const PointCloudFile direct = read_pcd(file);
  ASSERT_EQ(through_pipe.scan.points.size(), pts.size());
  ASSERT_EQ(direct.scan.points.size(), pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    ASSERT_EQ(through_pipe.scan.points[i].x, pts[i].x) << i;
    ASSERT_EQ(direct.scan.points[i].z, pts[i].z) << i;
    ASSERT_EQ(through_pipe.scan.points[i].time_s, direct.scan.points[i].time_s) << i;
  }
}

// A float64 coordinate can be finite and still beyond float's range (the fuzzer found one):
// the point is dropped like a NaN, not stored as inf.
TEST(Pcd, Float64CoordinateBeyondFloatRangeIsDropped) {
  const fs::path path = test::scratch_dir("pcd_huge") / "huge.pcd";
  std::string s = binary_header("x y z intensity", "8 4 4 8", "F F F F", 3);
  for (int i = 0; i < 3; ++i) {
    append<double>(s, i == 1 ? 1e300 : 1.0 + i);
    append<float>(s, 2.f);
    append<float>(s, 3.f);
    append<double>(s, i == 2 ? -1e300 : 7.0);  // intensity out of range: 0
  }
  write_bytes(path, s);
  const PointCloudFile f = read_pcd(path);
  ASSERT_EQ(f.scan.points.size(), 2u);
  EXPECT_FLOAT_EQ(f.scan.points[0].x, 1.f);
  EXPECT_FLOAT_EQ(f.scan.points[1].x, 3.f);
  EXPECT_FLOAT_EQ(f.scan.points[0].intensity, 7.f);
  EXPECT_FLOAT_EQ(f.scan.points[1].intensity, 0.f);
}

// A ring field stored as float may hold NaN or values beyond int16: the point keeps its
// coordinates and gets "no ring" (-1) or the nearest representable ring, never an undefined cast.
TEST(Pcd, FloatRingFieldWithNaNAndHugeValuesIsClamped) {
  const fs::path path = test::scratch_dir("pcd_ring_nan") / "ring.pcd";
  std::string s = binary_header("x y z ring", "4 4 4 4", "F F F F", 3);
  const float rings[] = {std::nanf(""), 1e9f, 5.f};
  for (int i = 0; i < 3; ++i) {
    append<float>(s, 1.f + i);
    append<float>(s, 2.f);
    append<float>(s, 3.f);
    append<float>(s, rings[i]);
  }
  write_bytes(path, s);
  const PointCloudFile f = read_pcd(path);
  ASSERT_EQ(f.scan.points.size(), 3u);
  EXPECT_TRUE(f.scan.has_ring);
  EXPECT_EQ(f.scan.points[0].ring, -1);
  EXPECT_EQ(f.scan.points[1].ring, 32767);
  EXPECT_EQ(f.scan.points[2].ring, 5);
  EXPECT_FLOAT_EQ(f.scan.points[0].x, 1.f);
}

// The field names are the bag readers' (field_names.hpp): a VeloView export's `laser_id` is the
// ring, `reflectance` the intensity, whatever the case.
TEST(Pcd, FieldNamesAreTheBagReadersOnes) {
  const fs::path path = test::scratch_dir("pcd_names") / "names.pcd";
  std::string s = binary_header("X Y Z Reflectance laser_id", "4 4 4 4 2", "F F F F U", 2);
  for (int i = 0; i < 2; ++i) {
    append<float>(s, 1.f + i);
    append<float>(s, 2.f);
    append<float>(s, 3.f);
    append<float>(s, 0.25f * (i + 1));
    append<std::uint16_t>(s, static_cast<std::uint16_t>(30 + i));
  }
  write_bytes(path, s);
  const PointCloudFile f = read_pcd(path);
  ASSERT_EQ(f.scan.points.size(), 2u);
  EXPECT_TRUE(f.scan.has_ring);
  EXPECT_EQ(f.scan.points[1].ring, 31);
  EXPECT_FLOAT_EQ(f.scan.points[1].intensity, 0.5f);
}

TEST(Pcd, UnusualLayoutFieldOrderPaddingFloat64Uint8CountAndNaN) {
  const fs::path path = test::scratch_dir("pcd_layout") / "odd.pcd";
  // intensity (uint8) first, a 3-byte padding field `_`, z before x, x/y float64, a normal of
  // COUNT 3, a uint32 nanosecond time; organized 2x2 with one NaN point.
  std::string s =
      "# odd\nVERSION .7\nFIELDS intensity _ z x y normal t\nSIZE 1 1 4 8 8 4 4\nTYPE U U F F F F U\n"
      "COUNT 1 3 1 1 1 3 1\nWIDTH 2\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\nDATA binary\n";
  for (int i = 0; i < 4; ++i) {
    append<std::uint8_t>(s, static_cast<std::uint8_t>(200 + i));
    s.append(3, '\0');
    append<float>(s, 0.5f * i);
    append<double>(s, i == 2 ? std::nan("") : 1.0 + i);
    append<double>(s, -2.0 * i);
    for (int k = 0; k < 3; ++k) append<float>(s, 9.f);
    append<std::uint32_t>(s, 25000000u * i);
  }
  write_bytes(path, s);
  const PointCloudFile f = read_pcd(path);
  EXPECT_EQ(f.declared_points, 4u);
  ASSERT_EQ(f.scan.points.size(), 3u);  // the NaN point is dropped
  EXPECT_TRUE(f.scan.has_time);
  EXPECT_FALSE(f.scan.has_ring);
  const LidarPoint& p = f.scan.points[2];  // the input's 4th point
  EXPECT_FLOAT_EQ(p.x, 4.0f);
  EXPECT_FLOAT_EQ(p.y, -6.0f);
  EXPECT_FLOAT_EQ(p.z, 1.5f);
  EXPECT_FLOAT_EQ(p.intensity, 203.f);
  EXPECT_NEAR(p.time_s, 0.075f, 1e-7);  // uint32 time: nanoseconds
  ASSERT_EQ(f.fields.size(), 7u);
  EXPECT_EQ(describe_fields(f.fields)[5], "normal:float32[3]");

  // The same cloud as ASCII, with float64 absolute times: the first point's time is the stamp.
  const fs::path ascii = path.parent_path() / "abs.pcd";
  write_bytes(ascii,
              "VERSION 0.7\nFIELDS x y z timestamp\nSIZE 4 4 4 8\nTYPE F F F F\nWIDTH 3\nHEIGHT 1\n"
              "POINTS 3\nDATA ascii\n1 2 3 1600000000.5\nnan nan nan 1600000000.55\n4 5 6 1600000000.6\n");
  const PointCloudFile a = read_pcd(ascii);
  ASSERT_EQ(a.scan.points.size(), 2u);
  EXPECT_DOUBLE_EQ(a.scan.timestamp_s, 1600000000.5);
  EXPECT_NEAR(a.scan.points[1].time_s, 0.1f, 1e-6);

  // float64 absolute nanoseconds (livox_ros_driver2), and a time field no reading fits.
  const fs::path ns = ascii.parent_path() / "abs_ns.pcd";
  write_bytes(ns, "VERSION 0.7\nFIELDS x y z timestamp\nSIZE 4 4 4 8\nTYPE F F F F\nWIDTH 2\nHEIGHT 1\n"
                  "POINTS 2\nDATA ascii\n1 2 3 1600000000000000000\n4 5 6 1600000000020000000\n");
  const PointCloudFile n = read_pcd(ns);
  EXPECT_TRUE(n.scan.has_time);
  EXPECT_NEAR(n.scan.timestamp_s, 1.6e9, 1e-3);
  EXPECT_NEAR(n.scan.points[1].time_s, 0.02f, 1e-6);
  const fs::path odd = ascii.parent_path() / "odd_time.pcd";
  write_bytes(odd, "VERSION 0.7\nFIELDS x y z time\nSIZE 4 4 4 4\nTYPE F F F F\nWIDTH 2\nHEIGHT 1\n"
                   "POINTS 2\nDATA ascii\n1 2 3 5\n4 5 6 5e9\n");
  EXPECT_FALSE(read_pcd(odd).scan.has_time);  // 5 .. 5e9: no reading (s or ns) fits one sweep
}

// binary_compressed is the binary layout's fields one after another (struct of arrays): read
// from those columns directly, it must give the binary file's scan for any layout, with NaN
// points dropped wherever they fall relative to the reader's blocks of 256 points.
TEST(Pcd, BinaryCompressedReadsAsBinaryForAnyLayoutAndAcrossBlocks) {
  const fs::path dir = test::scratch_dir("pcd_columns");
  // uint8 intensity, 3 padding bytes, float32 z, float64 x and y, a normal of COUNT 3, uint16
  // ring, uint32 nanosecond time: 1000 points, NaN x at block edges.
  const std::vector<std::size_t> widths = {1, 3, 4, 8, 8, 12, 2, 4};
  const std::size_t step = 42, n = 1000;
  const std::vector<std::size_t> nan_at = {0, 255, 256, 257, 511, 512, 999};
  std::string rows;
  for (std::size_t i = 0; i < n; ++i) {
    const bool nan = std::find(nan_at.begin(), nan_at.end(), i) != nan_at.end();
    append<std::uint8_t>(rows, static_cast<std::uint8_t>(i % 251));
    rows.append(3, '\0');
    append<float>(rows, 0.25f * static_cast<float>(i % 40));
    append<double>(rows, nan ? std::nan("") : 0.5 * static_cast<double>(i));
    append<double>(rows, -1.0 * static_cast<double>(i));
    for (int k = 0; k < 3; ++k) append<float>(rows, 9.f);
    append<std::uint16_t>(rows, static_cast<std::uint16_t>(i % 64));
    append<std::uint32_t>(rows, static_cast<std::uint32_t>(100000 * i));
  }
  ASSERT_EQ(rows.size(), n * step);
  std::string columns;
  std::size_t offset = 0;
  for (std::size_t w : widths) {
    for (std::size_t i = 0; i < n; ++i) columns.append(rows, i * step + offset, w);
    offset += w;
  }
  const std::string header =
      "VERSION 0.7\nFIELDS intensity _ z x y normal ring t\nSIZE 1 1 4 8 8 4 2 4\nTYPE U U F F F F U U\n"
      "COUNT 1 3 1 1 1 3 1 1\nWIDTH 1000\nHEIGHT 1\nPOINTS 1000\n";
  write_bytes(dir / "rows.pcd", header + "DATA binary\n" + rows);
  const auto packed = lzf_compress(reinterpret_cast<const unsigned char*>(columns.data()), columns.size());
  std::string compressed = header + "DATA binary_compressed\n";
  append<std::uint32_t>(compressed, static_cast<std::uint32_t>(packed.size()));
  append<std::uint32_t>(compressed, static_cast<std::uint32_t>(columns.size()));
  compressed.append(reinterpret_cast<const char*>(packed.data()), packed.size());
  write_bytes(dir / "columns.pcd", compressed);

  const Scan a = read_pcd(dir / "rows.pcd").scan;
  const Scan b = read_pcd(dir / "columns.pcd").scan;
  ASSERT_EQ(a.points.size(), n - nan_at.size());
  ASSERT_EQ(b.points.size(), a.points.size());
  EXPECT_TRUE(a.has_ring && b.has_ring && a.has_time && b.has_time);
  std::size_t k = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (std::find(nan_at.begin(), nan_at.end(), i) != nan_at.end()) continue;
    for (const Scan* s : {&a, &b}) {
      SCOPED_TRACE(s == &a ? "DATA binary" : "DATA binary_compressed");
      const LidarPoint& p = s->points[k];
      ASSERT_EQ(p.x, 0.5f * static_cast<float>(i)) << i;
      ASSERT_EQ(p.y, -static_cast<float>(i)) << i;
      ASSERT_EQ(p.z, 0.25f * static_cast<float>(i % 40)) << i;
      ASSERT_EQ(p.intensity, static_cast<float>(i % 251)) << i;
      ASSERT_EQ(p.ring, static_cast<std::int16_t>(i % 64)) << i;
      ASSERT_NEAR(p.time_s, 1e-4 * static_cast<double>(i), 1e-7) << i;  // nanoseconds
    }
    ++k;
  }
}

TEST(Pcd, ReadsFilesWrittenByOpen3D) {
  const fs::path dir = test::scratch_dir("pcd_open3d");
  open3d::geometry::PointCloud cloud;
  for (int i = 0; i < 1000; ++i) {
    cloud.points_.emplace_back(0.01 * i, -0.02 * i, 1.0 + 0.001 * i);
    cloud.normals_.emplace_back(0, 0, 1);
    cloud.colors_.emplace_back(0.5, 0.25, 1.0);
  }
  for (bool ascii : {true, false})
    for (bool compressed : {false, true}) {
      if (ascii && compressed) continue;
      const fs::path path = dir / (std::string(ascii ? "a" : "b") + (compressed ? "c" : "") + ".pcd");
      ASSERT_TRUE(open3d::io::WritePointCloud(path.string(), cloud,
                                              open3d::io::WritePointCloudOption(ascii, compressed)));
      const PointCloudFile f = read_pcd(path);
      ASSERT_EQ(f.scan.points.size(), 1000u) << path;
      EXPECT_NEAR(f.scan.points[999].x, 9.99, 1e-5) << path;
      EXPECT_NEAR(f.scan.points[999].y, -19.98, 1e-5) << path;
      EXPECT_NEAR(f.scan.points[999].z, 1.999, 1e-5) << path;
      EXPECT_GT(f.fields.size(), 3u) << path;  // normals and rgb are there, ignored
    }
}

TEST(Pcd, OurBinaryMapIsReadByOpen3D) {
  const fs::path path = test::scratch_dir("pcd_to_open3d") / "map.pcd";
  write_pcd(path, sample_points(777), PcdEncoding::kBinaryCompressed);
  open3d::geometry::PointCloud cloud;
  ASSERT_TRUE(open3d::io::ReadPointCloud(path.string(), cloud));
  EXPECT_EQ(cloud.points_.size(), 777u);
}

TEST(Pcd, TruncatedAndCorruptFilesGiveAnErrorNamingTheFile) {
  const fs::path dir = test::scratch_dir("pcd_bad");
  const auto pts = sample_points(300);
  for (auto enc : {PcdEncoding::kAscii, PcdEncoding::kBinary, PcdEncoding::kBinaryCompressed}) {
    const fs::path good = dir / ("good" + std::to_string(int(enc)) + ".pcd");
    write_pcd(good, pts, enc);
    std::ifstream in(good, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const fs::path cut = dir / ("cut" + std::to_string(int(enc)) + ".pcd");
    write_bytes(cut, bytes.substr(0, bytes.size() - 700));
    const std::string e = error_of(cut);
    EXPECT_NE(e.find(cut.string()), std::string::npos) << e;
    EXPECT_TRUE(e.find("truncated") != std::string::npos) << e;
  }
  // Compressed data with garbage in the middle of the LZF stream.
  const fs::path good = dir / "good2.pcd";
  std::ifstream in(good, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t data = bytes.find("DATA binary_compressed\n") + 23 + 8;
  for (std::size_t i = data; i < data + 64; ++i) bytes[i] = static_cast<char>(0xff);
  const fs::path corrupt = dir / "corrupt.pcd";
  write_bytes(corrupt, bytes);
  EXPECT_NE(error_of(corrupt).find("corrupt"), std::string::npos) << error_of(corrupt);

  const fs::path no_xyz = dir / "noxyz.pcd";
  write_bytes(no_xyz, "VERSION 0.7\nFIELDS a b c\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n");
  EXPECT_NE(error_of(no_xyz).find("no x, y and z"), std::string::npos) << error_of(no_xyz);
  // A corrupt WIDTH whose size products would overflow: an error, no allocation or crash.
  for (const char* data : {"ascii", "binary", "binary_compressed"}) {
    const fs::path huge = dir / (std::string("huge_") + data + ".pcd");
    write_bytes(huge, std::string("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 4611686018427387904\n"
                                  "HEIGHT 1\nDATA ") + data + "\n0123456789abcdef0123456789");
    EXPECT_NE(error_of(huge).find(huge.string()), std::string::npos) << data << ": " << error_of(huge);
  }
  const fs::path text = dir / "text.pcd";
  write_bytes(text, "hello world\n");
  EXPECT_NE(error_of(text).find("not a PCD file"), std::string::npos) << error_of(text);
  EXPECT_NE(error_of(dir / "missing.pcd").find("cannot open"), std::string::npos);
}
