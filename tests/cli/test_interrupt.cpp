// `scfloam run` stopped by SIGINT part way: every output is written for the frames processed,
// parses, and agrees with summary.json; the exit code is 130.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "scfloam/io/point_cloud_file.hpp"
#include "scfloam/io/trajectory.hpp"
#include "scfloam/loop/loops_csv.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kBinary = std::string(SCFLOAM_BINARY_DIR) + "/bin/scfloam";

int run_quietly(const std::string& args) {
  const std::string cmd = kBinary + " " + args + " >/dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Starts `scfloam args...` with stderr on a pipe; sends `sig` once a stderr line contains
// `trigger`; returns the exit code (128 + n for a death by signal n) and the stderr text.
std::pair<int, std::string> run_and_signal(const std::vector<std::string>& args,
                                           const std::string& trigger, int sig) {
  int fds[2];
  if (pipe(fds) != 0) return {-1, "pipe failed"};
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(fds[1], STDERR_FILENO);
    const int devnull = ::open("/dev/null", O_WRONLY);
    dup2(devnull, STDOUT_FILENO);
    close(fds[0]);
    std::vector<char*> argv{const_cast<char*>(kBinary.c_str())};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(kBinary.c_str(), argv.data());
    _exit(127);
  }
  close(fds[1]);
  std::string err;
  bool sent = false;
  char buf[512];
  FILE* in = fdopen(fds[0], "r");
  while (std::fgets(buf, sizeof buf, in)) {
    err += buf;
    if (!sent && std::string(buf).find(trigger) != std::string::npos) {
      kill(pid, sig);
      sent = true;
    }
  }
  std::fclose(in);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!sent) err += "\n(test: the trigger line never appeared)";
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), err};
}

}  // namespace

TEST(CliInterrupt, SigintWritesCompleteOutputsForTheFramesProcessed) {
  const fs::path dir = scfloam::test::scratch_dir("cli_interrupt");
  const fs::path seq = dir / "seq", out = dir / "out";
  constexpr int kFrames = 300;
  ASSERT_EQ(run_quietly("simulate --out " + seq.string() + " --frames " + std::to_string(kFrames) +
                        " --sensor vlp16 --no-traffic --quiet"),
            0);

  // The progress bar prints a line every 10 % when stderr is not a terminal: interrupt at 10 %.
  const auto [code, err] = run_and_signal(
      {"run", seq.string(), "--out", out.string(), "--mode", "optimized"}, "10%", SIGINT);
  ASSERT_EQ(code, 130) << err;
  EXPECT_NE(err.find("interrupted"), std::string::npos) << err;

  std::ifstream summary_in(out / "summary.json");
  const auto summary = nlohmann::json::parse(summary_in);
  EXPECT_TRUE(summary["interrupted"].get<bool>());
  const std::size_t frames = summary["frames"].get<std::size_t>();
  EXPECT_GE(frames, kFrames / 10u);
  EXPECT_LT(frames, static_cast<std::size_t>(kFrames));
  EXPECT_EQ(summary["timing_ms"]["features"]["count"].get<std::size_t>(), frames);

  // Every trajectory parses and has one pose per processed frame (keyframes: per keyframe).
  EXPECT_EQ(scfloam::read_kitti_poses(out / "poses_kitti.txt").size(), frames);
  EXPECT_EQ(scfloam::read_kitti_poses(out / "odometry_kitti.txt").size(), frames);
  EXPECT_EQ(scfloam::read_tum(out / "poses_tum.txt").poses.size(), frames);
  EXPECT_EQ(scfloam::read_kitti_poses(out / "keyframes_kitti.txt").size(),
            summary["keyframes"].get<std::size_t>());
  for (const auto& T : scfloam::read_kitti_poses(out / "poses_kitti.txt"))
    EXPECT_TRUE(T.matrix().allFinite());
  EXPECT_EQ(scfloam::read_loops_csv(out / "loops.csv").size(),
            summary["loops"]["candidates"].get<std::size_t>());

  // The map parses with the project's PCD reader, which refuses truncated data.
  const scfloam::PointCloudFile map = scfloam::read_pcd(out / "map.pcd");
  EXPECT_EQ(map.scan.points.size(), map.declared_points);
  EXPECT_GT(map.declared_points, 1000u);
  // No temporary file is left beside the outputs.
  for (const auto& entry : fs::directory_iterator(out))
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos) << entry.path();
}

TEST(CliInterrupt, SigtermIsHandledLikeSigint) {
  const fs::path dir = scfloam::test::scratch_dir("cli_interrupt_term");
  const fs::path seq = dir / "seq", out = dir / "out";
  ASSERT_EQ(run_quietly("simulate --out " + seq.string() +
                        " --frames 100 --sensor vlp16 --no-traffic --quiet"),
            0);
  const auto [code, err] = run_and_signal(
      {"run", seq.string(), "--out", out.string(), "--mode", "odometry"}, "10%", SIGTERM);
  ASSERT_EQ(code, 128 + SIGTERM) << err;
  std::ifstream summary_in(out / "summary.json");
  const auto summary = nlohmann::json::parse(summary_in);
  EXPECT_TRUE(summary["interrupted"].get<bool>());
  EXPECT_EQ(scfloam::read_kitti_poses(out / "poses_kitti.txt").size(),
            summary["frames"].get<std::size_t>());
}
