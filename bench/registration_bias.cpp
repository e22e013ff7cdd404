// Registration bias (docs/odometry.md, "Session 11"): is the scan-to-map match itself biased,
// before any drift accumulates? For every frame k of a simulated sequence with ground truth,
// a map is built from the features of frames k+OFF..k-1 (OFF < 0: the past, as the odometry's
// map is) or k+1..k+OFF (the future) placed at their TRUE poses, and frame k's features are
// registered to it starting from its TRUE pose. An unbiased match stays at the truth; the
// mean of the result's error over the frames is the bias one frame would add to the drift.
// Usage: registration_bias SEQ CONFIG.yaml [--frames 100] [--offset -1 ...]
//                          [--edges-only | --planes-only]
// Prints one line per offset: mean roll, pitch, yaw (deg) and x, y, z (m) in the lidar frame,
// and the mean number of edge and plane matches the final round accepted.
#include <cstdio>
#include <algorithm>
#include <cmath>
#include <exception>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "scfloam/config.hpp"
#include "scfloam/error.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/odometry/odometry.hpp"
#include "scfloam/registration/scan_to_map.hpp"

using namespace scfloam;

namespace {

struct Bias {
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();
  double edge_matches = 0, plane_matches = 0;  // mean accepted matches of the final round
  int frames = 0;
};

Bias measure(const std::vector<FeatureCloud>& edges, const std::vector<FeatureCloud>& planes,
             const PoseList& truth, const SlamConfig& config, int offset, bool use_edges, bool use_planes) {
  Bias bias;
  const FeatureCloud none;
  const int n = static_cast<int>(edges.size()), margin = std::abs(offset) + 1;
  for (int k = margin; k + margin < n; ++k) {
    FeatureMap map(config.odometry.registration, config.odometry.map);
    const int first = offset < 0 ? k + offset : k + 1, last = offset < 0 ? k - 1 : k + offset;
    for (int j = first; j <= last; ++j) map.insert(edges[j], planes[j], truth[j]);
    const RegistrationResult r = register_features(use_edges ? edges[k] : none, use_planes ? planes[k] : none, map,
                                                   truth[k], config.odometry.registration,
                                                   config.odometry.registration.outer_iterations_max);
    const Eigen::AngleAxisd error(truth[k].rotation().transpose() * r.T_world_lidar.rotation());
    bias.rotation_deg += error.angle() * error.axis() * 180.0 / M_PI;
    bias.translation_m += truth[k].rotation().transpose() * (r.T_world_lidar.translation() - truth[k].translation());
    bias.edge_matches += r.edge_matches;
    bias.plane_matches += r.plane_matches;
    ++bias.frames;
  }
  if (bias.frames > 0) {
    bias.rotation_deg /= bias.frames;
    bias.translation_m /= bias.frames;
    bias.edge_matches /= bias.frames;
    bias.plane_matches /= bias.frames;
  }
  return bias;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s SEQ CONFIG.yaml [--frames N] [--offset K ...] [--edges-only|--planes-only]\n",
                 argv[0]);
    return 2;
  }
  try {
    const SlamConfig config = load_config(argv[2]);
    const KittiSequence seq = KittiSequence::open(argv[1]);
    std::size_t frames = 100;
    std::vector<int> offsets;
    bool use_edges = true, use_planes = true;
    for (int i = 3; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--frames" && i + 1 < argc) frames = std::stoul(argv[++i]);
      else if (a == "--offset" && i + 1 < argc) offsets.push_back(std::stoi(argv[++i]));
      else if (a == "--edges-only") use_planes = false;
      else if (a == "--planes-only") use_edges = false;
      else throw Error("unknown argument `" + a + "`");
    }
    if (offsets.empty()) offsets = {-1, 1, -5, 5};
    const PoseList truth = seq.ground_truth_lidar();
    if (truth.empty()) throw file_error(seq.dir(), "has no poses.txt: the bias needs ground truth");
    frames = std::min({frames, seq.size(), truth.size()});
    // The odometry's own feature clouds (after its preprocessing), one frame at a time.
    Odometry odometry(config.odometry);
    std::vector<FeatureCloud> edges, planes;
    for (std::size_t k = 0; k < frames; ++k) {
      OdometryResult r = odometry.process(seq.load(k));
      // A setting check that switched replaces its trial's features.
      for (std::size_t i = 0; i < r.revised.size(); ++i) {
        edges[k - r.revised.size() + i] = std::move(r.revised[i].edges);
        planes[k - r.revised.size() + i] = std::move(r.revised[i].planes);
      }
      edges.push_back(std::move(r.edges));
      planes.push_back(std::move(r.planes));
    }
    std::printf("offset  frames  roll_deg  pitch_deg  yaw_deg      x_m      y_m      z_m  edge_matches  plane_matches\n");
    for (const int offset : offsets) {
      if (offset == 0) continue;
      const Bias b = measure(edges, planes, truth, config, offset, use_edges, use_planes);
      std::printf("%6d  %6d  %8.4f  %9.4f  %7.4f  %7.4f  %7.4f  %7.4f  %12.0f  %13.0f\n", offset, b.frames,
                  b.rotation_deg.x(), b.rotation_deg.y(), b.rotation_deg.z(), b.translation_m.x(),
                  b.translation_m.y(), b.translation_m.z(), b.edge_matches, b.plane_matches);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "registration_bias: %s\n", e.what());
    return 1;
  }
  return 0;
}
