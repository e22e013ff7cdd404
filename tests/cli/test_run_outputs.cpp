// `scfloam run` on a folder of PCD scans: same trajectory as the same scans as a KITTI
// directory, the map files (PCD, PLY, keyframes), --frame, --force, --sensor.
#include <gtest/gtest.h>

#include "cli/run_cli.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "scfloam/io/kitti.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "scfloam/io/trajectory.hpp"
#include "scfloam/sim/simulate.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using namespace scfloam;

namespace {

using scfloam::test::Outcome;
using scfloam::test::run_cli;

// 30 simulated HDL-64 scans as a KITTI directory and the same scans as binary_compressed PCDs
// with a timestamps file (built once for the suite).
class RunOutputs : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = test::scratch_dir("run_outputs");
    sim::SimConfig cfg;
    cfg.frames = 30;
    cfg.seed = 4;
    sim::simulate_sequence(cfg, root_ / "kitti", false);
    const KittiSequence seq = KittiSequence::open(root_ / "kitti");
    fs::create_directories(root_ / "pcd");
    for (std::size_t i = 0; i < seq.size(); ++i)
      write_pcd(root_ / "pcd" / ("scan" + std::to_string(i) + ".pcd"), seq.load(i).points,
                PcdEncoding::kBinaryCompressed);
    fs::copy_file(root_ / "kitti" / "times.txt", root_ / "stamps.txt");
    // Three of them with ring and time fields, as a raw driver's scans come.
    fs::create_directories(root_ / "pcd_time");
    for (std::size_t i = 0; i < 3; ++i)
      write_pcd(root_ / "pcd_time" / ("scan" + std::to_string(i) + ".pcd"), seq.load(i).points,
                PcdEncoding::kBinary, /*with_ring_time=*/true);
  }
  static fs::path root_;
};
fs::path RunOutputs::root_;

}  // namespace

TEST_F(RunOutputs, PcdFolderGivesTheSameTrajectoryAsTheKittiDirectory) {
  const std::string common = " --mode odometry --deterministic --quiet --frame lidar";
  Outcome a = run_cli("run " + (root_ / "kitti").string() + " -o " + (root_ / "out_kitti").string() + common);
  ASSERT_EQ(a.exit_code, 0) << a.output;
  Outcome b = run_cli("run " + (root_ / "pcd").string() + " --timestamps " + (root_ / "stamps.txt").string() +
                      " -o " + (root_ / "out_pcd").string() + common);
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const auto ta = read_tum(root_ / "out_kitti" / "poses_tum.txt");
  const auto tb = read_tum(root_ / "out_pcd" / "poses_tum.txt");
  ASSERT_EQ(ta.poses.size(), 30u);
  ASSERT_EQ(tb.poses.size(), 30u);
  double max_diff_m = 0;
  for (std::size_t i = 0; i < 30; ++i) {
    EXPECT_DOUBLE_EQ(ta.stamps_s[i], tb.stamps_s[i]);
    max_diff_m = std::max(max_diff_m, (ta.poses[i].translation() - tb.poses[i].translation()).norm());
  }
  // The same float32 points in the same order: the same trajectory, byte for byte.
  EXPECT_LT(max_diff_m, 1e-6);
  auto bytes = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  EXPECT_EQ(bytes(root_ / "out_kitti" / "poses_tum.txt"), bytes(root_ / "out_pcd" / "poses_tum.txt"));
  EXPECT_EQ(bytes(root_ / "out_kitti" / "map.pcd"), bytes(root_ / "out_pcd" / "map.pcd"));
  EXPECT_GT(ta.poses.back().translation().norm(), 5.0);  // it moved
}

TEST_F(RunOutputs, MapPlyKeyframesFrameAndForce) {
  const fs::path out = root_ / "nested" / "out_maps";  // parent folders are created
  const std::string input = (root_ / "pcd").string();
  Outcome r = run_cli("run " + input + " -o " + out.string() +
                      " --mode odometry --quiet -n 12 --ply --save-keyframes --map-voxel 0.5");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const PointCloudFile pcd = read_pcd(out / "map.pcd");
  const PointCloudFile ply = read_ply(out / "map.ply");
  EXPECT_EQ(ply.format, "PLY binary_little_endian");
  ASSERT_GT(pcd.scan.points.size(), 1000u);
  ASSERT_EQ(ply.scan.points.size(), pcd.scan.points.size());
  std::size_t with_intensity = 0;
  for (std::size_t i = 0; i < ply.scan.points.size(); ++i) {
    EXPECT_EQ(ply.scan.points[i].x, pcd.scan.points[i].x);
    with_intensity += ply.scan.points[i].intensity > 0.05f;
  }
  EXPECT_GT(with_intensity, ply.scan.points.size() / 2);  // simulated reflectance is kept
  // keyframes/: one cloud per keyframe and their poses; rebuilding gives the map's extent.
  const PoseList kf_poses = read_kitti_poses(out / "keyframes" / "poses_kitti.txt");
  ASSERT_GE(kf_poses.size(), 2u);
  EXPECT_EQ(kf_poses.size(), read_kitti_poses(out / "keyframes_kitti.txt").size());
  for (std::size_t k = 0; k < kf_poses.size(); ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "%06zu.pcd", k);
    EXPECT_TRUE(fs::exists(out / "keyframes" / name)) << name;
  }
  const PointCloudFile last = read_pcd(out / "keyframes" / "000001.pcd");
  const Eigen::Vector3f p(last.scan.points[0].x, last.scan.points[0].y, last.scan.points[0].z);
  const Eigen::Vector3f world = kf_poses[1].cast<float>() * p;
  float nearest = 1e9f;
  for (const auto& q : pcd.scan.points) nearest = std::min(nearest, (Eigen::Vector3f(q.x, q.y, q.z) - world).norm());
  EXPECT_LT(nearest, 1.0f);  // a keyframe point moved by its pose lies on the map (0.5 m voxels)

  // An existing result is refused without --force; with it the run goes ahead.
  r = run_cli("run " + input + " -o " + out.string() + " --mode odometry --quiet -n 3");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("--force"), std::string::npos) << r.output;
  EXPECT_EQ(read_kitti_poses(out / "poses_kitti.txt").size(), 12u);  // untouched
  r = run_cli("run " + input + " -o " + out.string() + " --mode odometry --quiet -n 3 --force");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_kitti_poses(out / "poses_kitti.txt").size(), 3u);

  // --frame camera needs Tr: the PCD folder has none (refused before running); KITTI has one.
  r = run_cli("run " + input + " -o " + (root_ / "cam").string() + " --mode odometry --quiet -n 3 --frame camera");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("--frame camera"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("Tr"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(root_ / "cam" / "summary.json"));
  r = run_cli("run " + (root_ / "kitti").string() + " -o " + (root_ / "cam2").string() +
              " --mode odometry --quiet -n 3 --frame camera");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  r = run_cli("run " + input + " -o " + (root_ / "f").string() + " --quiet -n 3 --frame sideways");
  EXPECT_EQ(r.exit_code, 1);
}

TEST_F(RunOutputs, SensorPresetsLoadAndLivoxSaysWhyNot) {
  for (const char* sensor : {"kitti", "hdl64", "hdl32", "vlp16", "os1-64", "os1-128"}) {
    const Outcome r = run_cli("run " + (root_ / "pcd").string() + " -o " + (root_ / "preset" / sensor).string() +
                              " --mode odometry --quiet -n 2 --sensor " + sensor);
    EXPECT_EQ(r.exit_code, 0) << sensor << ": " << r.output;
  }
  // Without a preset a folder of HDL-64E scans runs on KITTI's defaults (its beams cannot tell
  // KITTI's sensor from another), with KITTI's elevation correction on trial: summary.json
  // says so (two frames decide nothing); the hdl64 preset corrects nothing and checks nothing.
  Outcome plain = run_cli("run " + (root_ / "pcd").string() + " -o " + (root_ / "preset" / "none").string() +
                          " --mode odometry --quiet -n 2");
  EXPECT_EQ(plain.exit_code, 0) << plain.output;
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(root_ / "preset" / "none" / "summary.json"))["elevation_check"]["check"],
            "trial");
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(root_ / "preset" / "hdl64" / "summary.json"))["elevation_check"]["check"],
            "off");
  // A KITTI sequence with the hdl64 preset (no correction of KITTI's elevation error) is told
  // about --sensor kitti; with the KITTI preset it is not.
  for (const char* sensor : {"hdl64", "kitti"}) {
    const Outcome k = run_cli("run " + (root_ / "kitti").string() + " -o " + (root_ / "preset" / "k").string() +
                              " --mode odometry --quiet -f -n 2 --sensor " + sensor);
    EXPECT_EQ(k.exit_code, 0) << k.output;
    EXPECT_EQ(k.output.find("--sensor kitti corrects") != std::string::npos, std::string(sensor) == "hdl64")
        << sensor << ": " << k.output;
  }
  // Scans with per-point times run without deskew (KITTI's preset given) are told about it;
  // with a raw-driver preset, or without times, they are not. Without --sensor the guessed
  // HDL-64E is deskewed (a raw driver's scans), unless --config turns deskew off.
  const std::string deskew_note = "per-point times but deskew is off";
  { std::ofstream(root_ / "no_deskew.yaml") << "odometry:\n  preprocess:\n    deskew: false\n"; }
  const std::string no_deskew = " --config " + (root_ / "no_deskew.yaml").string();
  for (const std::string extra : {"", " --sensor kitti", " --sensor hdl64", no_deskew.c_str()}) {
    const fs::path out = root_ / "preset" / "t";
    const Outcome t = run_cli("run " + (root_ / "pcd_time").string() + " -o " + out.string() +
                              " --mode odometry --quiet -f -n 2" + extra);
    ASSERT_EQ(t.exit_code, 0) << t.output;
    const bool deskew_off = extra == " --sensor kitti" || extra == no_deskew;
    EXPECT_EQ(t.output.find(deskew_note) != std::string::npos, deskew_off) << extra << ": " << t.output;
    const auto summary = nlohmann::json::parse(std::ifstream(out / "summary.json"));
    EXPECT_EQ(summary["sensor"]["deskew"].get<bool>(), !deskew_off) << extra;
    EXPECT_EQ(summary["sensor"]["from"], extra.find("--sensor") == std::string::npos ? "scans" : "--sensor") << extra;
  }
  EXPECT_EQ(plain.output.find(deskew_note), std::string::npos) << plain.output;
  Outcome r = run_cli("run " + (root_ / "pcd").string() + " -o " + (root_ / "lv").string() + " --sensor livox");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("ring"), std::string::npos) << r.output;
  r = run_cli("run " + (root_ / "pcd").string() + " -o " + (root_ / "xx").string() + " --sensor hdl99");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("hdl99"), std::string::npos) << r.output;
  // --config on top of a preset: its keys are checked and its errors name it.
  { std::ofstream(root_ / "bad.yaml") << "odometry:\n  preprocess:\n    max_range_mm: 5\n"; }
  r = run_cli("run " + (root_ / "pcd").string() + " -o " + (root_ / "bc").string() +
              " --sensor vlp16 --config " + (root_ / "bad.yaml").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("bad.yaml"), std::string::npos) << r.output;
  // The file's keys override the preset's: the map crop follows max_range_m (preset: 90 m).
  { std::ofstream(root_ / "ok.yaml") << "odometry:\n  preprocess:\n    max_range_m: 20\n"; }
  auto farthest_m = [](const fs::path& cloud) {
    float r = 0;
    for (const auto& p : read_pcd(cloud).scan.points) r = std::max(r, std::hypot(p.x, p.y));
    return r;
  };
  r = run_cli("run " + (root_ / "pcd").string() + " -o " + (root_ / "okc").string() +
              " --mode odometry --quiet -n 2 --save-keyframes --sensor vlp16 --config " + (root_ / "ok.yaml").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_LE(farthest_m(root_ / "okc" / "keyframes" / "000000.pcd"), 20.5f);
  r = run_cli("run " + (root_ / "pcd").string() + " -o " + (root_ / "okp").string() +
              " --mode odometry --quiet -n 2 --save-keyframes --sensor vlp16");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_GT(farthest_m(root_ / "okp" / "keyframes" / "000000.pcd"), 40.f);
}
