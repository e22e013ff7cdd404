// open_scan_source / detect_input_kind: every kind of input, and what an unknown one says.
#include <gtest/gtest.h>

#include <fstream>

#include "scfloam/error.hpp"
#include "scfloam/io/input_inspect.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using namespace scfloam;

namespace {
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(InputDetection, KittiFolderFileAndUnknown) {
  const fs::path dir = test::scratch_dir("detect");
  LidarPoint p;
  p.x = 5;
  write_pcd(dir / "one.pcd", {p, p}, PcdEncoding::kBinaryCompressed);
  EXPECT_EQ(detect_input_kind(dir / "one.pcd"), InputKind::kScanFile);
  EXPECT_EQ(detect_input_kind(dir), InputKind::kScanFolder);
  const auto single = open_scan_source(dir / "one.pcd");
  ASSERT_EQ(single->size(), 1u);
  EXPECT_EQ(single->load(0).points.size(), 2u);

  { std::ofstream(dir / "notes.txt") << "x\n"; }
  const std::string e = error_of([&] { open_scan_source(dir / "notes.txt"); });
  EXPECT_NE(e.find("notes.txt"), std::string::npos) << e;
  for (const char* looked : {"KITTI", "velodyne/", "bag", ".pcd", ".ply", ".bin"})
    EXPECT_NE(e.find(looked), std::string::npos) << looked << " in " << e;
  EXPECT_NE(error_of([&] { open_scan_source(dir / "nothing"); }).find("no such file"), std::string::npos);

  // --timestamps is for folders and files only.
  SCFLOAM_SHARED_DATA_OR_SKIP(seq, "kitti/scans/08");
  EXPECT_EQ(detect_input_kind(seq), InputKind::kKitti);
  ScanSourceOptions options;
  options.timestamps_file = dir / "notes.txt";
  EXPECT_NE(error_of([&] { open_scan_source(seq, options); }).find("--timestamps"), std::string::npos);
}

TEST(InputDetection, InspectKittiAndACorruptFile) {
  SCFLOAM_SHARED_DATA_OR_SKIP(seq, "kitti/scans/08");
  const InputInfo info = inspect_input(seq);
  EXPECT_EQ(info.kind, "KITTI sequence");
  EXPECT_EQ(info.scans, 10u);
  EXPECT_EQ(info.point_fields.size(), 4u);
  EXPECT_GT(info.points_in_first_scan, 100000u);
  EXPECT_GT(info.end_time_s, info.start_time_s);

  const fs::path dir = test::scratch_dir("detect_corrupt");
  { std::ofstream(dir / "broken.pcd") << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 10\nHEIGHT 1\nPOINTS 10\nDATA binary\n123"; }
  const std::string e = error_of([&] { inspect_input(dir / "broken.pcd"); });
  EXPECT_NE(e.find("broken.pcd"), std::string::npos) << e;
  EXPECT_NE(e.find("truncated"), std::string::npos) << e;
}
