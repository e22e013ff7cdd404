// Scan readers' speed on one real KITTI HDL-64E scan (../shared/data/kitti/scans/05, ~122k
// points), as the input thread pays it per frame: on 2 cores it competes with the odometry.
//   build*/bin/bench_readers [--benchmark_filter=...]
// KittiBin: the .bin as KITTI ships it. Pcd*: the same points written as PCD with ring and
// time fields (the simulator's raw-scan layout). PointCloud2: the same points in a Velodyne
// driver's message layout (x y z, intensity at 16, ring at 20, time at 24, 32-byte points),
// converted from memory, as the bag readers do after decoding.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "scfloam/io/kitti.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "scfloam/io/pointcloud2.hpp"

namespace {
using namespace scfloam;
namespace fs = std::filesystem;

fs::path scan_path() {
  if (const char* env = std::getenv("SCFLOAM_KITTI_SCANS")) return fs::path(env) / "velodyne/000000.bin";
  return fs::path(SCFLOAM_BENCH_SHARED_DIR) / "data/kitti/scans/05/velodyne/000000.bin";
}

// The real scan with a ring and a firing time per point, as a raw driver would give them.
const std::vector<LidarPoint>& points() {
  static const std::vector<LidarPoint> pts = [] {
    std::vector<LidarPoint> p = read_kitti_bin(scan_path());
    for (std::size_t i = 0; i < p.size(); ++i) {
      p[i].ring = static_cast<std::int16_t>(i % 64);
      p[i].time_s = 0.1f * static_cast<float>(i) / static_cast<float>(p.size());
    }
    return p;
  }();
  return pts;
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "scfloam_bench_readers";
  fs::create_directories(dir);
  return dir / name;
}

void BM_KittiBin(benchmark::State& state) {
  const fs::path path = scan_path();
  for (auto _ : state) benchmark::DoNotOptimize(read_kitti_bin(path));
  state.counters["points"] = static_cast<double>(points().size());
}
BENCHMARK(BM_KittiBin)->Unit(benchmark::kMillisecond);

void BM_Pcd(benchmark::State& state, PcdEncoding encoding, const char* file) {
  const fs::path path = scratch(file);
  write_pcd(path, points(), encoding, /*with_ring_time=*/true);
  for (auto _ : state) benchmark::DoNotOptimize(read_pcd(path));
  std::error_code ec;
  fs::remove(path, ec);
  fs::remove(path.parent_path(), ec);  // only once empty
}
BENCHMARK_CAPTURE(BM_Pcd, binary, PcdEncoding::kBinary, "binary.pcd")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Pcd, binary_compressed, PcdEncoding::kBinaryCompressed, "compressed.pcd")
    ->Unit(benchmark::kMillisecond);

void BM_PointCloud2(benchmark::State& state) {
  const auto& pts = points();
  constexpr std::uint32_t kStep = 32;
  std::vector<std::uint8_t> data(pts.size() * kStep, 0);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    std::uint8_t* p = data.data() + i * kStep;
    const std::uint16_t ring = static_cast<std::uint16_t>(pts[i].ring);
    std::memcpy(p + 0, &pts[i].x, 4);
    std::memcpy(p + 4, &pts[i].y, 4);
    std::memcpy(p + 8, &pts[i].z, 4);
    std::memcpy(p + 16, &pts[i].intensity, 4);
    std::memcpy(p + 20, &ring, 2);
    std::memcpy(p + 24, &pts[i].time_s, 4);
  }
  PointCloud2View v;
  v.height = 1;
  v.width = static_cast<std::uint32_t>(pts.size());
  v.fields = {{"x", 0, 7, 1}, {"y", 4, 7, 1}, {"z", 8, 7, 1},
              {"intensity", 16, 7, 1}, {"ring", 20, 4, 1}, {"time", 24, 7, 1}};
  v.point_step = kStep;
  v.row_step = kStep * v.width;
  v.data = data.data();
  v.data_size = data.size();
  for (auto _ : state) benchmark::DoNotOptimize(pointcloud2_to_scan(v, "bench"));
}
BENCHMARK(BM_PointCloud2)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
