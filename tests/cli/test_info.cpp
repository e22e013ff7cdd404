// `scfloam info`: text and JSON reports, and a clear error for a file it cannot read.
#include <gtest/gtest.h>

#include "cli/run_cli.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <nlohmann/json.hpp>

#include "scfloam/io/point_cloud_file.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using namespace scfloam;

namespace {

using scfloam::test::Outcome;
using scfloam::test::run_cli;

}  // namespace

TEST(CliInfo, PcdFolderTextAndJson) {
  const fs::path dir = test::scratch_dir("cli_info");
  std::vector<LidarPoint> pts(50);
  for (std::size_t i = 0; i < pts.size(); ++i) pts[i].x = static_cast<float>(i);
  for (int i = 0; i < 3; ++i) write_pcd(dir / ("s" + std::to_string(i) + ".pcd"), pts, PcdEncoding::kBinary, true);
  Outcome r = run_cli("info " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* expected : {"PCD folder", "scans:     3", "ring:uint16", "time:float32",
                               "points in the first scan: 50", "0.1 s apart"})
    EXPECT_NE(r.output.find(expected), std::string::npos) << expected << " in\n" << r.output;

  r = run_cli("info --json " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["scans"], 3);
  EXPECT_EQ(j["points_in_first_scan"], 50);
  EXPECT_EQ(j["point_fields"].size(), 6u);
  EXPECT_EQ(j["point_fields"][0], "x:float32");
  EXPECT_DOUBLE_EQ(j["end_time_s"].get<double>(), 0.2);
  EXPECT_TRUE(j["notes"].is_array());
  EXPECT_TRUE(j["topics"].is_array());
}

// Scans without point times: info says what deskew would take from their azimuths.
TEST(CliInfo, ScansWithoutTimesShowTheirSweep) {
  const fs::path dir = test::scratch_dir("cli_info_sweep");
  std::vector<LidarPoint> sweep;  // 16 beams, 900 columns, clockwise from 90 deg
  for (int c = 0; c < 900; ++c)
    for (int b = 0; b < 16; ++b) {
      const double az = (90.0 - 0.4 * c) * M_PI / 180, el = (-15.0 + 2.0 * b) * M_PI / 180, r = 10.0 + (c % 7);
      LidarPoint p;
      p.x = static_cast<float>(r * std::cos(el) * std::cos(az));
      p.y = static_cast<float>(r * std::cos(el) * std::sin(az));
      p.z = static_cast<float>(r * std::sin(el));
      sweep.push_back(p);
    }
  for (int i = 0; i < 2; ++i) write_pcd(dir / ("s" + std::to_string(i) + ".pcd"), sweep, PcdEncoding::kBinary, false);
  Outcome r = run_cli("info " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string said = "from the azimuth: column by column, turning clockwise, seam at ";
  const std::size_t at = r.output.find(said);
  ASSERT_NE(at, std::string::npos) << r.output;
  EXPECT_NEAR(std::stod(r.output.substr(at + said.size())), 90.0, 0.3) << r.output;  // half a column
  // Shuffled, the same points show no sweep.
  std::shuffle(sweep.begin(), sweep.end(), std::mt19937(3));
  write_pcd(dir / "s0.pcd", sweep, PcdEncoding::kBinary, false);
  r = run_cli("info " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("the point order shows no sweep"), std::string::npos) << r.output;
}

TEST(CliInfo, KittiSequence) {
  SCFLOAM_SHARED_DATA_OR_SKIP(seq, "kitti/scans/00");
  const Outcome r = run_cli("info --json " + seq.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["kind"], "KITTI sequence");
  EXPECT_EQ(j["scans"], 10);
  EXPECT_GT(j["points_in_first_scan"].get<int>(), 100000);
  bool blurred = false;
  for (const auto& note : j["notes"]) blurred = blurred || note.get<std::string>().find("beams: elevations blurred") == 0;
  EXPECT_TRUE(blurred) << j["notes"];
}

TEST(CliInfo, UnreadableInputsSayWhyAndExitNonZero) {
  const fs::path dir = test::scratch_dir("cli_info_bad");
  { std::ofstream(dir / "cut.ply", std::ios::binary) << "ply\nformat binary_little_endian 1.0\nelement vertex 9\nproperty float x\nproperty float y\nproperty float z\nend_header\nabc"; }
  Outcome r = run_cli("info " + (dir / "cut.ply").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("cut.ply"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("truncated"), std::string::npos) << r.output;
  r = run_cli("info " + (dir / "absent").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("no such file"), std::string::npos) << r.output;
}
