// `scfloam render`: bird's-eye PNG of a sequence accumulated with its poses.
#include <filesystem>

#include "command_registry.hpp"
#include "scfloam/error.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/io/trajectory.hpp"
#include "scfloam/sim/birdseye.hpp"

namespace {
namespace fs = std::filesystem;

struct RenderArgs {
  fs::path sequence, out, poses;
  scfloam::sim::BirdseyeOptions options;
  bool quiet = false;
};

void run(const RenderArgs& a) {
  const auto seq = scfloam::KittiSequence::open(a.sequence);
  scfloam::PoseList T_lidar;
  if (!a.poses.empty()) {
    const auto cam = scfloam::read_kitti_poses(a.poses);
    const auto Tr = seq.calib().has_Tr ? seq.calib().T_cam0_velo : scfloam::kitti_default_Tr();
    T_lidar = scfloam::camera_to_lidar_poses(cam, Tr);
    if (T_lidar.size() < seq.size())
      throw scfloam::file_error(a.poses, "has " + std::to_string(T_lidar.size()) + " poses for " +
                                             std::to_string(seq.size()) + " scans");
  } else {
    if (!seq.ground_truth_camera())
      throw scfloam::file_error(a.sequence, "has no poses.txt (pass --poses FILE)");
    T_lidar = seq.ground_truth_lidar();
  }
  const auto img = scfloam::sim::render_birdseye(seq, T_lidar, a.options, !a.quiet);
  scfloam::sim::write_png_rgb(a.out, img.width, img.height, img.rgb);
  if (!a.quiet)
    std::fprintf(stderr, "render: %dx%d pixels at %.3f m/pixel -> %s\n", img.width, img.height,
                 img.resolution_m, a.out.string().c_str());
}

scfloam::cli::RegisterCommand reg("render", [](CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  auto* sub = app.add_subcommand("render", "Bird's-eye PNG of a KITTI sequence accumulated with its poses");
  sub->add_option("sequence", args->sequence, "KITTI odometry sequence directory")->required();
  sub->add_option("--out", args->out, "PNG file to write")->required();
  sub->add_option("--every", args->options.every, "Use every N-th scan")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--resolution", args->options.resolution_m, "Metres per pixel")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--range", args->options.max_range_m, "Ignore points farther than this from the sensor (m)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--poses", args->poses, "Render with these poses (KITTI camera-0 file) instead of poses.txt")
      ->check(CLI::ExistingFile);
  sub->add_flag("--quiet", args->quiet, "No progress output");
  sub->callback([args] { run(*args); });
});

}  // namespace
