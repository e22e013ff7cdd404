// `scfloam run` end to end through the built binary: outputs, errors, exit codes.
#include <gtest/gtest.h>

#include "cli/run_cli.hpp"

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "scfloam/io/trajectory.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;

namespace {

using scfloam::test::Outcome;
using scfloam::test::run_cli;

nlohmann::json read_json(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

}  // namespace

TEST(CliRun, OdometryOnRealKittiScansWritesEveryOutput) {
  SCFLOAM_SHARED_DATA_OR_SKIP(seq, "kitti/scans/05");
  const fs::path out = scfloam::test::scratch_dir("cli_run_real05");
  const Outcome r = run_cli("run " + seq.string() + " --out " + out.string() + " --mode odometry --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* name : {"poses_kitti.txt", "poses_tum.txt", "odometry_kitti.txt", "summary.json",
                           "keyframes_kitti.txt", "map.pcd"})
    EXPECT_TRUE(fs::exists(out / name)) << name;
  EXPECT_EQ(scfloam::read_kitti_poses(out / "poses_kitti.txt").size(), 10u);
  EXPECT_EQ(scfloam::read_tum(out / "poses_tum.txt").poses.size(), 10u);
  const auto summary = read_json(out / "summary.json");
  EXPECT_EQ(summary["frames"], 10);
  for (const char* key : {"keyframes", "wall_s", "peak_rss_mb", "timing_ms"})
    EXPECT_TRUE(summary.contains(key)) << key;
  for (const char* stage : {"features", "registration"})
    for (const char* stat : {"median", "mean", "p95", "count"})
      EXPECT_TRUE(summary["timing_ms"][stage].contains(stat)) << stage << "." << stat;
  EXPECT_EQ(summary["timing_ms"]["features"]["count"], 10);
  // Frames per correspondence-round count: every frame once; the first frame matches nothing
  // (0 rounds), the next start from F-LOAM's 12 initial rounds and may converge sooner.
  ASSERT_TRUE(summary.contains("registration_rounds"));
  int counted = 0;
  for (const auto& [rounds, frames] : summary["registration_rounds"].items()) {
    EXPECT_LE(std::stoi(rounds), 12) << rounds;
    counted += frames.get<int>();
  }
  EXPECT_EQ(counted, 10);
  // The KITTI preset's fixed elevation correction, unchanged without the online estimate.
  EXPECT_EQ(summary["elevation_correction_deg"]["first_frame"], 0.22);
  EXPECT_EQ(summary["elevation_correction_deg"]["last_frame"], 0.22);
  // KITTI's HDL-64E elevations are blurred (lasers at different heights): F-LOAM's table stays.
  EXPECT_EQ(summary["rings"]["source"], "table");
  EXPECT_EQ(summary["rings"]["beams"], 64);
  EXPECT_TRUE(summary.contains("accuracy"));  // poses.txt is there: ATE against it
  // The car moves about 5 m forward over these frames (ground truth).
  EXPECT_GT(scfloam::read_kitti_poses(out / "poses_kitti.txt").back().translation().z(), 4.0);

  // A second run into the same folder is refused without --force, and the result survives.
  const Outcome again = run_cli("run " + seq.string() + " --out " + out.string() + " --mode odometry --quiet");
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_NE(again.output.find("--force"), std::string::npos) << again.output;
  EXPECT_TRUE(fs::exists(out / "summary.json"));
}

// Rings of a sensor the chosen preset does not describe: a table that merges beams is replaced
// by the learned beams, one that only crops some is kept and the run says what it leaves out.
TEST(CliRun, RingsOfAnotherSensorAreLearnedOrTheCropIsReported) {
  const fs::path dir = scfloam::test::scratch_dir("cli_run_rings");
  ASSERT_EQ(run_cli("simulate --out " + (dir / "v32").string() + " --frames 4 --sensor vlp32c --quiet").exit_code, 0);
  ASSERT_EQ(run_cli("simulate --out " + (dir / "v16").string() + " --frames 4 --sensor vlp16 --quiet").exit_code, 0);

  Outcome r = run_cli("run " + (dir / "v32").string() + " --sensor hdl32 -m odometry -q -o " + (dir / "o32").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("rings from the scans' own 32 beams"), std::string::npos) << r.output;
  auto rings = read_json(dir / "o32" / "summary.json")["rings"];
  EXPECT_EQ(rings["source"], "learned");
  EXPECT_EQ(rings["beams"], 32);
  EXPECT_NEAR(rings["highest_deg"].get<double>(), 15.0, 0.02);
  EXPECT_NEAR(rings["lowest_deg"].get<double>(), -25.0, 0.02);

  // --sensor auto: the same beams, learned whatever a table would say.
  r = run_cli("run " + (dir / "v32").string() + " --sensor auto -m odometry -q -o " + (dir / "oauto").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  rings = read_json(dir / "oauto" / "summary.json")["rings"];
  EXPECT_EQ(rings["source"], "learned");
  EXPECT_EQ(rings["beams"], 32);

  // KITTI's HDL-64E table on a VLP-16 (--sensor kitti; without --sensor the scans choose
  // vlp16): no two beams share a ring, seven are above +2 deg.
  r = run_cli("run " + (dir / "v16").string() + " --sensor kitti -m odometry -q -o " + (dir / "o16").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("leaves out 7 of the scans' 16 beams"), std::string::npos) << r.output;
  rings = read_json(dir / "o16" / "summary.json")["rings"];
  EXPECT_EQ(rings["source"], "table");
  EXPECT_EQ(rings["scan_beams"], 16);
  EXPECT_EQ(rings["cropped_beams"], 7);
}

// KITTI's own HDL-64E scans have blurred elevations: --sensor auto refuses them and says why.
TEST(CliRun, AutoRingsOnKittiScansStopWithAnError) {
  SCFLOAM_SHARED_DATA_OR_SKIP(seq, "kitti/scans/05");
  const fs::path out = scfloam::test::scratch_dir("cli_run_auto_kitti");
  const Outcome r = run_cli("run " + seq.string() + " --sensor auto -m odometry -q -o " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("do not form distinct beams"), std::string::npos) << r.output;
}

TEST(CliRun, BadInputGivesAClearErrorAndExitCode) {
  const fs::path dir = scfloam::test::scratch_dir("cli_run_bad");
  Outcome r = run_cli("run " + (dir / "missing").string() + " --out " + (dir / "o").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("error: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("missing"), std::string::npos) << r.output;

  fs::create_directories(dir / "seq" / "velodyne");
  { std::ofstream bin(dir / "seq" / "velodyne" / "000000.bin", std::ios::binary); bin << "12345"; }
  { std::ofstream calib(dir / "seq" / "calib.txt"); calib << "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n"; }
  r = run_cli("run " + (dir / "seq").string() + " --out " + (dir / "o2").string() + " --quiet");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("000000.bin"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("multiple of 16"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "o2" / "summary.json"));

  r = run_cli("run " + (dir / "seq").string() + " --mode nonsense");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("nonsense"), std::string::npos) << r.output;

  r = run_cli("run");  // missing the required input: a command-line error
  EXPECT_EQ(r.exit_code, 2) << r.output;
}
