// sim_digest: one line per simulator configuration with a hash of what the seed produced —
// the world's primitives, the trajectory, the traffic plan and, for short drives, the bytes
// of the written sequence. scripts/test.sh runs it from the gcc build and from the clang
// sanitizer build and requires identical output: a seed must give the same sequence on every
// compiler (rng.hpp says how that breaks). Usage: sim_digest [SHARED_DIR]
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <unistd.h>

#include "scfloam/sim/degenerate.hpp"
#include "scfloam/sim/simulate.hpp"
#include "scfloam/sim/traffic.hpp"

namespace fs = std::filesystem;
using namespace scfloam::sim;

namespace {
// FNV-1a over raw bytes: exact equality is the point, not strength.
struct Digest {
  std::uint64_t h = 1469598103934665603ULL;
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ULL;
  }
  template <typename T>
  void value(T x) { bytes(&x, sizeof x); }
};

std::string scenario_digest(const SimConfig& config) {
  const Scenario sc = build_scenario(config);
  Digest world, path, traffic;
  for (const Primitive& p : sc.world.primitives) {
    world.value(static_cast<int>(p.shape));
    world.value(static_cast<int>(p.kind));
    for (float x : {p.reflectance, p.mean_free_path_m, p.pass_prob}) world.value(x);
    for (double x : {p.cx, p.cy, p.cos_yaw, p.sin_yaw, p.hx, p.hy, p.z0, p.z1}) world.value(x);
  }
  for (std::size_t k = 0; k < sc.frames; ++k) {
    const auto T = sc.frame_pose(k).matrix();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 4; ++j) path.value(T(i, j));
  }
  const Traffic plan(sc.trajectory, sc.world, config.traffic, config.seed);
  for (const Mover& m : plan.movers()) {
    traffic.value(static_cast<int>(m.kind));
    for (double x : {m.t_on_s, m.t_off_s, m.s0_m, m.t0_s, m.speed_mps, m.lateral_m, m.gap_m,
                     m.wobble_m, m.wobble_rad_s, m.wobble_phase, m.half_len_m, m.half_width_m,
                     m.body_bottom_m, m.body_top_m, m.cabin_half_len_m, m.cabin_half_width_m,
                     m.cabin_top_m})
      traffic.value(x);
    traffic.value(m.reflectance);
  }
  char line[160];
  std::snprintf(line, sizeof line, "%zu primitives %016llx, %zu frames %016llx, %zu movers %016llx",
                sc.world.primitives.size(), static_cast<unsigned long long>(world.h), sc.frames,
                static_cast<unsigned long long>(path.h), plan.movers().size(),
                static_cast<unsigned long long>(traffic.h));
  return line;
}

// Every file simulate_sequence writes, in name order.
std::string sequence_digest(const SimConfig& config, const fs::path& dir) {
  fs::remove_all(dir);
  simulate_sequence(config, dir, false);
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  Digest d;
  for (const fs::path& f : files) {
    const std::string name = fs::relative(f, dir).string();
    d.bytes(name.data(), name.size());
    std::ifstream in(f, std::ios::binary);
    const std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    d.bytes(content.data(), content.size());
  }
  fs::remove_all(dir);
  char line[80];
  std::snprintf(line, sizeof line, "%zu files %016llx", files.size(), static_cast<unsigned long long>(d.h));
  return line;
}

SimConfig config(const std::string& route, std::uint64_t seed, std::size_t frames) {
  SimConfig c;
  c.route = route;
  c.seed = seed;
  c.frames = frames;
  return c;
}
}  // namespace

int main(int argc, char** argv) {
  const fs::path shared = argc > 1 ? fs::path(argv[1]) : fs::path();
  const fs::path replay = shared / "data/kitti/ground-truth/poses/05.txt";
  const fs::path tmp = fs::temp_directory_path() / ("scfloam-sim-digest-" + std::to_string(::getpid()));
  try {
    // Worlds: the route kinds and every degenerate scene, several seeds.
    for (std::uint64_t seed = 1; seed <= 3; ++seed)
      std::printf("world loops seed %llu: %s\n", static_cast<unsigned long long>(seed),
                  scenario_digest(config("loops", seed, 1200)).c_str());
    std::printf("world straight seed 1: %s\n", scenario_digest(config("straight", 1, 1200)).c_str());
    for (const std::string& scene : degenerate_scenario_names())
      for (std::uint64_t seed = 1; seed <= 2; ++seed) {
        SimConfig c = config("loops", seed, 0);
        c.scenario = scene;
        std::printf("world %s seed %llu: %s\n", scene.c_str(), static_cast<unsigned long long>(seed),
                    scenario_digest(c).c_str());
      }
    if (shared.empty() || !fs::exists(replay)) {
      std::printf("world kitti-05 replay: skipped (no %s)\n", replay.c_str());
    } else {
      SimConfig c = config("kitti", 3, 200);
      c.replay_poses = replay;
      std::printf("world kitti-05 replay: %s\n", scenario_digest(c).c_str());
    }
    // Scans: two frames of a 64- and a 16-beam sensor, and of a motion-distorted 32-beam one
    // written as PCD with per-point times.
    for (const std::string& sensor : {std::string("hdl64"), std::string("vlp16")}) {
      SimConfig c = config("loops", 5, 2);
      c.sensor = sensor;
      std::printf("scans %s: %s\n", sensor.c_str(), sequence_digest(c, tmp).c_str());
    }
    SimConfig distorted = config("loops", 7, 2);
    distorted.sensor = "hdl32";
    distorted.motion_distortion = true;
    distorted.scan_format = "pcd";
    std::printf("scans hdl32 distorted pcd: %s\n", sequence_digest(distorted, tmp).c_str());
  } catch (const std::exception& e) {
    std::error_code ec;
    fs::remove_all(tmp, ec);
    std::fprintf(stderr, "sim_digest: %s\n", e.what());
    return 1;
  }
  return 0;
}
