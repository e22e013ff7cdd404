// `scfloam run` on ROS bags end to end: the same simulated scans as a KITTI directory, as a
// ROS 1 bag (librosbag's writer, LZ4 chunks), a ROS 2 MCAP file (zstd chunks) and a ROS 2
// sqlite3 bag, each beside an IMU topic so the PointCloud2 topic must be picked. The points
// are the same float32 values in the same order, so every input must give the KITTI run's
// trajectory.
#include <gtest/gtest.h>

#include "cli/run_cli.hpp"
#include "io/test_bag_writers.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "scfloam/io/kitti.hpp"
#include "scfloam/io/trajectory.hpp"
#include "scfloam/sim/simulate.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;
using namespace scfloam;

namespace {

using scfloam::test::Outcome;
using scfloam::test::run_cli;

constexpr std::size_t kFrames = 25;
constexpr double kEpochS = 1700000000.0;  // bag stamps: a real-looking epoch, not zero

class RunBags : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = test::scratch_dir("run_bags");
    sim::SimConfig cfg;
    cfg.frames = kFrames;
    cfg.seed = 7;
    sim::simulate_sequence(cfg, root_ / "kitti", false);
    const KittiSequence seq = KittiSequence::open(root_ / "kitti");
    // As a KITTI scan has them: x, y, z, intensity; no ring and no point time.
    test::CloudLayout layout;
    layout.ring = false;
    layout.time = test::TimeField::None;
    std::vector<test::OwnedCloud> clouds;
    for (std::size_t i = 0; i < seq.size(); ++i) {
      const Scan s = seq.load(i);
      clouds.push_back(test::make_cloud(s.points, kEpochS + s.timestamp_s, layout));
    }
    test::write_ros1_bag(root_ / "drive.bag", {"/velodyne_points"}, clouds);

    test::McapTestWriter mcap("zstd", true, true, 4);
    const auto imu = mcap.add_topic("/imu", "sensor_msgs/msg/Imu");
    const auto lidar = mcap.add_topic("/points", "sensor_msgs/msg/PointCloud2");
    std::vector<std::pair<std::int64_t, std::vector<std::uint8_t>>> msgs;
    for (const auto& c : clouds) {
      const auto ns = c.meta.stamp_sec * 1000000000LL + c.meta.stamp_nanosec;
      mcap.write(lidar, static_cast<std::uint64_t>(ns), test::encode_cdr(c, false));
      mcap.write(imu, static_cast<std::uint64_t>(ns) + 1, {0, 1, 0, 0});
      msgs.push_back({ns, test::encode_cdr(c, false)});
    }
    test::write_bytes(root_ / "drive.mcap", mcap.finish());
    test::write_sqlite_bag(root_ / "drive.db3", "/points", "cdr", msgs, true);
  }

  // Runs odometry on `input` into out_<name> and returns its LiDAR-frame trajectory.
  static StampedTrajectory run(const fs::path& input, const std::string& name) {
    const fs::path out = root_ / ("out_" + name);
    const Outcome r = run_cli("run " + input.string() + " -o " + out.string() +
                              " --mode odometry --deterministic --quiet --force");
    EXPECT_EQ(r.exit_code, 0) << name << ": " << r.output;
    return read_tum(out / "poses_tum.txt");
  }
  static fs::path root_;
};
fs::path RunBags::root_;

TEST_F(RunBags, EveryBagKindGivesTheKittiDirectorysTrajectory) {
  const StampedTrajectory kitti = run(root_ / "kitti", "kitti");
  ASSERT_EQ(kitti.poses.size(), kFrames);
  EXPECT_GT(kitti.poses.back().translation().norm(), 3.0);  // it moved
  for (const char* name : {"drive.bag", "drive.mcap", "drive.db3"}) {
    const StampedTrajectory bag = run(root_ / name, name);
    ASSERT_EQ(bag.poses.size(), kFrames) << name;
    double max_diff_m = 0, max_stamp_diff_s = 0;
    for (std::size_t i = 0; i < kFrames; ++i) {
      max_diff_m = std::max(max_diff_m, (bag.poses[i].translation() - kitti.poses[i].translation()).norm());
      max_diff_m = std::max(max_diff_m, (bag.poses[i].linear() - kitti.poses[i].linear()).norm());
      // Stamps come from the messages' headers: the KITTI stamps shifted by the epoch.
      max_stamp_diff_s = std::max(max_stamp_diff_s, std::abs(bag.stamps_s[i] - kEpochS - kitti.stamps_s[i]));
    }
    EXPECT_LT(max_diff_m, 1e-6) << name;
    EXPECT_LT(max_stamp_diff_s, 1e-6) << name;
  }
}

TEST_F(RunBags, TopicChoiceAndAMissingTopicSayWhatTheBagHolds) {
  // --topic names the cloud topic explicitly; a topic that is not there is a clear error.
  const Outcome ok = run_cli("run " + (root_ / "drive.mcap").string() + " --topic /points -n 3 -o " +
                             (root_ / "out_topic").string() + " --mode odometry --quiet --force");
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
  EXPECT_EQ(read_tum(root_ / "out_topic" / "poses_tum.txt").poses.size(), 3u);
  const Outcome bad = run_cli("run " + (root_ / "drive.mcap").string() + " --topic /nothing -o " +
                              (root_ / "out_bad").string() + " --mode odometry --quiet --force");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.output.find("drive.mcap"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("/nothing"), std::string::npos) << bad.output;
}

}  // namespace
