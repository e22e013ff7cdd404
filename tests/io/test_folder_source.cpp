// Folders of scans: natural order, stamps (timestamps file, names, 0.1 s), mixed kinds.
#include <gtest/gtest.h>

#include <fstream>

#include "scfloam/error.hpp"
#include "scfloam/io/folder_source.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using namespace scfloam;

namespace {

// Scan i has one point at x = i, so the order is visible after loading.
void write_marked_scans(const fs::path& dir, const std::vector<std::string>& names) {
  for (std::size_t i = 0; i < names.size(); ++i) {
    LidarPoint p;
    p.x = static_cast<float>(std::stoi(names[i].substr(4)));  // "scanN.pcd" -> N
    write_pcd(dir / names[i], {p}, PcdEncoding::kBinary);
  }
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(NaturalOrder, NumbersCompareByValue) {
  EXPECT_TRUE(natural_less("scan2.pcd", "scan10.pcd"));
  EXPECT_FALSE(natural_less("scan10.pcd", "scan2.pcd"));
  EXPECT_TRUE(natural_less("000009.bin", "000010.bin"));
  EXPECT_TRUE(natural_less("a9", "b1"));
  EXPECT_TRUE(natural_less("scan2", "scan2b"));
  EXPECT_TRUE(natural_less("x1y2", "x1y10"));
  EXPECT_FALSE(natural_less("same", "same"));
}

TEST(FolderSource, NaturalOrderAndEvenlySpacedStampsByDefault) {
  const fs::path dir = test::scratch_dir("folder_order");
  write_marked_scans(dir, {"scan10.pcd", "scan2.pcd", "scan1.pcd", "scan11.pcd"});
  { std::ofstream(dir / "README.txt") << "not a scan\n"; }
  const auto source = open_scan_source(dir);
  ASSERT_EQ(source->size(), 4u);
  const float expected[] = {1, 2, 10, 11};
  for (std::size_t i = 0; i < 4; ++i) {
    const Scan s = source->load(i);
    EXPECT_EQ(s.points.at(0).x, expected[i]);
    EXPECT_NEAR(s.timestamp_s, 0.1 * i, 1e-12);
  }
  EXPECT_NE(source->describe().find("0.1 s apart"), std::string::npos) << source->describe();
  EXPECT_FALSE(source->T_cam0_lidar());
}

TEST(FolderSource, TimestampsFileGivesStampsAndItsCountMustMatch) {
  const fs::path dir = test::scratch_dir("folder_stamps");
  const fs::path scans = dir / "scans";
  fs::create_directories(scans);
  write_marked_scans(scans, {"scan1.pcd", "scan2.pcd", "scan3.pcd"});
  { std::ofstream(dir / "good.txt") << "100.5\n100.6\n100.75\n"; }
  { std::ofstream(dir / "short.txt") << "1\n2\n"; }
  ScanSourceOptions options;
  options.timestamps_file = dir / "good.txt";
  const auto source = open_scan_source(scans, options);
  EXPECT_DOUBLE_EQ(source->load(2).timestamp_s, 100.75);
  options.timestamps_file = dir / "short.txt";
  const std::string e = error_of([&] { open_scan_source(scans, options); });
  EXPECT_NE(e.find("short.txt"), std::string::npos) << e;
  EXPECT_NE(e.find("2 timestamps for 3 scans"), std::string::npos) << e;
}

TEST(FolderSource, StampsFromFileNames) {
  const fs::path dir = test::scratch_dir("folder_named");
  LidarPoint p;
  write_pcd(dir / "1583836591.100000.pcd", {p}, PcdEncoding::kAscii);
  write_pcd(dir / "1583836591.200000.pcd", {p}, PcdEncoding::kAscii);
  const auto source = open_scan_source(dir);
  EXPECT_NEAR(source->load(1).timestamp_s, 1583836591.2, 1e-6);
  const fs::path ns = test::scratch_dir("folder_named_ns");
  write_ply(ns / "1583836591100000000.ply", {p}, PlyEncoding::kAscii);
  write_ply(ns / "1583836591150000000.ply", {p}, PlyEncoding::kAscii);
  const InputInfo info = inspect_file_list(list_scan_folder(ns), {});
  EXPECT_NEAR(info.end_time_s - info.start_time_s, 0.05, 1e-6);
  EXPECT_EQ(info.kind, "PLY folder (PLY ascii)");
}

TEST(FolderSource, MixedKindsAndEmptyFoldersAreErrors) {
  const fs::path dir = test::scratch_dir("folder_mixed");
  LidarPoint p;
  write_pcd(dir / "a.pcd", {p}, PcdEncoding::kBinary);
  write_ply(dir / "b.ply", {p}, PlyEncoding::kAscii);
  const std::string e = error_of([&] { open_scan_source(dir); });
  EXPECT_NE(e.find("mixes"), std::string::npos) << e;
  const fs::path empty = test::scratch_dir("folder_empty");
  const std::string e2 = error_of([&] { open_scan_source(empty); });
  EXPECT_NE(e2.find("no scans"), std::string::npos) << e2;
  EXPECT_NE(e2.find(".pcd"), std::string::npos) << e2;
}

TEST(FolderSource, BinFolderReadsLikeKitti) {
  SCFLOAM_SHARED_DATA_OR_SKIP(seq, "kitti/scans/00");
  const auto folder = open_scan_source(seq / "velodyne");
  const KittiSequence kitti = KittiSequence::open(seq);
  ASSERT_EQ(folder->size(), kitti.size());
  const Scan a = folder->load(3), b = kitti.load(3);
  ASSERT_EQ(a.points.size(), b.points.size());
  EXPECT_EQ(a.points[1000].x, b.points[1000].x);
  EXPECT_EQ(a.points[1000].intensity, b.points[1000].intensity);
}

TEST(FolderSource, SingleBinFileRoundTrip) {
  const fs::path dir = test::scratch_dir("folder_bin");
  std::vector<LidarPoint> pts(100);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    pts[i].x = 0.5f * i;
    pts[i].y = -0.25f * i;
    pts[i].z = 1.f;
    pts[i].intensity = 0.01f * i;
  }
  write_kitti_bin(dir / "000000.bin", pts);
  const auto source = open_scan_source(dir / "000000.bin");
  const Scan s = source->load(0);
  ASSERT_EQ(s.points.size(), pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    EXPECT_EQ(s.points[i].x, pts[i].x);
    EXPECT_EQ(s.points[i].intensity, pts[i].intensity);
  }
  EXPECT_NE(source->describe().find("KITTI .bin file"), std::string::npos) << source->describe();
}
