// `scfloam run` without --sensor takes the preset the scans' beams call for
// (io/sensor_detection.hpp): a VLP-16 sequence runs exactly as with --sensor vlp16, not on
// KITTI's settings, and the choice is recorded in summary.json and shown by `scfloam info`.
#include <gtest/gtest.h>

#include "cli/run_cli.hpp"

#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "scfloam/sim/simulate.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using scfloam::test::Outcome;
using scfloam::test::run_cli;

namespace {

std::string file_text(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

nlohmann::json summary_of(const fs::path& out) { return nlohmann::json::parse(file_text(out / "summary.json")); }

TEST(RunSensor, AVlp16SequenceWithoutSensorRunsOnTheVlp16Preset) {
  const fs::path root = scfloam::test::scratch_dir("run_sensor");
  scfloam::sim::SimConfig cfg;
  cfg.frames = 25;
  cfg.seed = 6;
  cfg.sensor = "vlp16";
  scfloam::sim::simulate_sequence(cfg, root / "vlp16", false);
  const std::string seq = (root / "vlp16").string();
  auto run = [&](const std::string& name, const std::string& extra) {
    const Outcome r = run_cli("run " + seq + " -o " + (root / name).string() + " --mode odometry -f" + extra);
    EXPECT_EQ(r.exit_code, 0) << name << ": " << r.output;
    return r;
  };
  const Outcome guessed = run("guessed", "");
  run("given", " --quiet --sensor vlp16");
  run("kitti", " --quiet --sensor kitti");

  EXPECT_NE(guessed.output.find("sensor: vlp16, from the scans (16 beams"), std::string::npos) << guessed.output;
  const auto s = summary_of(root / "guessed");
  EXPECT_EQ(s["sensor"]["preset"], "vlp16");
  EXPECT_EQ(s["sensor"]["from"], "scans");
  EXPECT_EQ(summary_of(root / "given")["sensor"]["from"], "--sensor");
  // Same settings, same trajectory; KITTI's settings give another one.
  const std::string poses = file_text(root / "guessed" / "poses_kitti.txt");
  ASSERT_FALSE(poses.empty());
  EXPECT_EQ(poses, file_text(root / "given" / "poses_kitti.txt"));
  EXPECT_NE(poses, file_text(root / "kitti" / "poses_kitti.txt"));

  const Outcome info = run_cli("info " + seq);
  EXPECT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("without --sensor uses vlp16"), std::string::npos) << info.output;
}

}  // namespace
