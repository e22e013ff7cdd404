// PLY: round trips of the three encodings, unusual vertex layouts, files written by Open3D,
// truncated files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>

#include "scfloam/error.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using namespace scfloam;

namespace {

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

template <typename T>
void append_be(std::string& s, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof v);
  std::reverse(b, b + sizeof(T));  // this test runs on little-endian hosts (x86, arm64)
  s.append(b, sizeof b);
}

template <typename T>
void append_le(std::string& s, T v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof v);
}

std::string error_of(const fs::path& path) {
  try {
    read_ply(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Ply, RoundTripOfEveryEncoding) {
  const fs::path dir = test::scratch_dir("ply_round_trip");
  std::vector<LidarPoint> pts(2000);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    pts[i].x = 0.37f * i;
    pts[i].y = -1.1f * i + 0.3f;
    pts[i].z = 1e-3f * i;
    pts[i].intensity = static_cast<float>(i % 100) / 7.f;
  }
  for (auto enc : {PlyEncoding::kAscii, PlyEncoding::kBinaryLittleEndian, PlyEncoding::kBinaryBigEndian}) {
    const fs::path path = dir / ("m" + std::to_string(int(enc)) + ".ply");
    write_ply(path, pts, enc);
    const PointCloudFile f = read_ply(path);
    ASSERT_EQ(f.scan.points.size(), pts.size()) << path;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      ASSERT_EQ(f.scan.points[i].x, pts[i].x) << path << " " << i;
      ASSERT_EQ(f.scan.points[i].y, pts[i].y);
      ASSERT_EQ(f.scan.points[i].z, pts[i].z);
      ASSERT_EQ(f.scan.points[i].intensity, pts[i].intensity);
    }
  }
}

TEST(Ply, BigEndianDoublesUcharIntensityPropertyOrderAndAnElementBeforeTheVertices) {
  const fs::path path = test::scratch_dir("ply_layout") / "odd.ply";
  std::string s =
      "ply\r\nformat binary_big_endian 1.0\r\ncomment odd layout\r\nelement camera 1\r\n"
      "property list uchar int ids\r\nelement vertex 3\r\nproperty uchar reflectivity\r\n"
      "property double z\r\nproperty double y\r\nproperty double x\r\nproperty ushort ring\r\n"
      "element face 0\r\nproperty list uchar int vertex_indices\r\nend_header\r\n";
  append_be<std::uint8_t>(s, 2);  // the camera's list: 2 ints
  append_be<std::int32_t>(s, 7);
  append_be<std::int32_t>(s, 8);
  for (int i = 0; i < 3; ++i) {
    append_be<std::uint8_t>(s, static_cast<std::uint8_t>(250 + i));
    append_be<double>(s, 0.25 * i);
    append_be<double>(s, -1.0 * i);
    append_be<double>(s, 100.0 + i);
    append_be<std::uint16_t>(s, static_cast<std::uint16_t>(31 - i));
  }
  write_bytes(path, s);
  const PointCloudFile f = read_ply(path);
  ASSERT_EQ(f.scan.points.size(), 3u);
  EXPECT_TRUE(f.scan.has_ring);
  EXPECT_FLOAT_EQ(f.scan.points[2].x, 102.f);
  EXPECT_FLOAT_EQ(f.scan.points[2].y, -2.f);
  EXPECT_FLOAT_EQ(f.scan.points[2].z, 0.5f);
  EXPECT_FLOAT_EQ(f.scan.points[2].intensity, 252.f);
  EXPECT_EQ(f.scan.points[2].ring, 29);
  EXPECT_EQ(f.format, "PLY binary_big_endian");

  const fs::path ascii = path.parent_path() / "odd_ascii.ply";
  write_bytes(ascii,
              "ply\nformat ascii 1.0\nelement note 2\nproperty int a\nelement vertex 2\nproperty float y\n"
              "property float x\nproperty float z\nproperty float intensity\nend_header\n1\n2\n"
              "1 2 3 4\n5 6 nan 8\n");
  const PointCloudFile a = read_ply(ascii);
  ASSERT_EQ(a.scan.points.size(), 1u);  // the NaN vertex is dropped
  EXPECT_FLOAT_EQ(a.scan.points[0].x, 2.f);
  EXPECT_FLOAT_EQ(a.scan.points[0].intensity, 4.f);
}

TEST(Ply, ReadsFilesWrittenByOpen3D) {
  const fs::path dir = test::scratch_dir("ply_open3d");
  open3d::geometry::PointCloud cloud;
  for (int i = 0; i < 500; ++i) {
    cloud.points_.emplace_back(0.5 * i, 1.0, -0.25 * i);
    cloud.colors_.emplace_back(1.0, 0.0, 0.5);
  }
  for (bool ascii : {true, false}) {
    const fs::path path = dir / (ascii ? "a.ply" : "b.ply");
    ASSERT_TRUE(open3d::io::WritePointCloud(path.string(), cloud, open3d::io::WritePointCloudOption(ascii)));
    const PointCloudFile f = read_ply(path);
    ASSERT_EQ(f.scan.points.size(), 500u) << path;
    EXPECT_NEAR(f.scan.points[499].x, 249.5, 1e-4);
    EXPECT_NEAR(f.scan.points[499].z, -124.75, 1e-4);
  }
}

TEST(Ply, TruncatedAndBrokenFilesGiveAnErrorNamingTheFile) {
  const fs::path dir = test::scratch_dir("ply_bad");
  std::vector<LidarPoint> pts(100);
  for (auto enc : {PlyEncoding::kAscii, PlyEncoding::kBinaryLittleEndian}) {
    const fs::path good = dir / ("g" + std::to_string(int(enc)) + ".ply");
    write_ply(good, pts, enc);
    std::ifstream in(good, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const fs::path cut = dir / ("cut" + std::to_string(int(enc)) + ".ply");
    write_bytes(cut, bytes.substr(0, bytes.size() - 300));
    const std::string e = error_of(cut);
    EXPECT_NE(e.find(cut.string()), std::string::npos) << e;
    EXPECT_NE(e.find("truncated"), std::string::npos) << e;
    const fs::path header_only = dir / ("h" + std::to_string(int(enc)) + ".ply");
    write_bytes(header_only, bytes.substr(0, 40));
    EXPECT_NE(error_of(header_only).find("end_header"), std::string::npos) << error_of(header_only);
  }
  for (const char* format : {"ascii", "binary_little_endian"}) {
    const fs::path huge = dir / (std::string("huge_") + format + ".ply");
    write_bytes(huge, std::string("ply\nformat ") + format + " 1.0\nelement junk 4611686018427387904\n"
                      "element vertex 4611686018427387904\nproperty float x\nproperty float y\n"
                      "property float z\nend_header\n0123456789abcdef");
    EXPECT_NE(error_of(huge).find(huge.string()), std::string::npos) << format << ": " << error_of(huge);
  }
  const fs::path mesh = dir / "mesh.ply";
  write_bytes(mesh, "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n3 0 1 2\n");
  EXPECT_NE(error_of(mesh).find("no vertex element"), std::string::npos) << error_of(mesh);
  const fs::path not_ply = dir / "x.ply";
  write_bytes(not_ply, "solid cube\n");
  EXPECT_NE(error_of(not_ply).find("not a PLY file"), std::string::npos);
}
