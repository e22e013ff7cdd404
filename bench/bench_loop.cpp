// Loop detection cost per keyframe (issue 4 target: <= 2 ms with 5000 keyframes in the
// database, descriptor + search + alignment). The query clouds are a simulated HDL-64 sweep
// (raw) and its F-LOAM feature clouds (edges 0.4 m + planes 0.8 m voxels); the database holds
// 5000 distinct synthetic places.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>

#include "../tests/loop/synthetic_scene.hpp"
#include "scfloam/features/feature_extractor.hpp"
#include "scfloam/loop/loop_detector.hpp"
#include "scfloam/registration/voxel_filter.hpp"
#include "scfloam/sim/scan.hpp"
#include "scfloam/sim/simulate.hpp"
#include "scfloam/stats.hpp"

namespace {

using namespace scfloam;

struct QueryClouds {
  Scan raw;
  FeatureCloud edges, planes;
};

const QueryClouds& query_clouds() {
  static const QueryClouds clouds = [] {
    QueryClouds c;
    const sim::Scenario scenario = sim::make_loops_scenario(1, 50);
    const sim::SensorModel sensor = sim::sensor_preset("hdl64");
    sim::SweepPoses poses;
    poses.T_world_lidar = scenario.frame_pose(25);
    c.raw = sim::render_scan(scenario.world, sensor, sim::draw_beam_calibration(sensor, 1), poses, 1, 25);
    FeatureExtractor extractor(PreprocessConfig{}, RingConfig{}, FeatureConfig{});
    FeatureCloud edges, planes;
    extractor.extract(c.raw.points, c.raw.has_ring, edges, planes);
    c.edges = voxel_downsample(edges, FeatureConfig{}.edge_leaf_m);
    c.planes = voxel_downsample(planes, FeatureConfig{}.plane_leaf_m);
    return c;
  }();
  return clouds;
}

// Descriptors of `count` distinct places (built once, shared by the benchmarks).
const std::vector<ScanContext>& database(int count) {
  static std::vector<ScanContext> descriptors;
  const ScanContextConfig config;
  while (static_cast<int>(descriptors.size()) < count) {
    const auto seed = static_cast<std::uint32_t>(descriptors.size() + 1);
    descriptors.push_back(make_scan_context(
        test::random_place(seed, 100 + seed % 200, 20 + seed % 40), config));
  }
  return descriptors;
}

// A detector holding `count` keyframes 10 m apart.
std::unique_ptr<LoopDetector> filled_detector(int count) {
  auto detector = std::make_unique<LoopDetector>(LoopDetectionConfig{});
  const auto& db = database(count);
  for (int i = 0; i < count; ++i)
    detector->add_keyframe(i, test::pose_xy_yaw(10.0 * i, 0, 0), db[i]);
  return detector;
}

void BM_DescriptorFromFeatures(benchmark::State& state) {
  const auto& q = query_clouds();
  for (auto _ : state) benchmark::DoNotOptimize(make_scan_context(q.edges, q.planes, ScanContextConfig{}));
  state.counters["points"] = static_cast<double>(q.edges.size() + q.planes.size());
}
BENCHMARK(BM_DescriptorFromFeatures)->Unit(benchmark::kMillisecond);

void BM_DescriptorFromRawScan(benchmark::State& state) {
  const auto& q = query_clouds();
  for (auto _ : state) benchmark::DoNotOptimize(make_scan_context(q.raw.points, ScanContextConfig{}));
  state.counters["points"] = static_cast<double>(q.raw.points.size());
}
BENCHMARK(BM_DescriptorFromRawScan)->Unit(benchmark::kMillisecond);

void BM_AlignTenCandidates(benchmark::State& state) {
  const auto& db = database(11);
  for (auto _ : state)
    for (int i = 1; i <= 10; ++i) benchmark::DoNotOptimize(align_scan_contexts(db[0], db[i], 0.1));
}
BENCHMARK(BM_AlignTenCandidates)->Unit(benchmark::kMillisecond);

// The whole per-keyframe cost: descriptor from the feature clouds, ring-key search (tree
// rebuilds included as they fall due), alignment and gate of 10 candidates. Each iteration
// adds a keyframe, so the database grows from range(0) by the iteration count.
void BM_QueryWithFeatureCloud(benchmark::State& state) {
  const int keyframes = static_cast<int>(state.range(0));
  auto detector = filled_detector(keyframes);
  const auto& q = query_clouds();
  std::vector<double> samples;
  std::int64_t frame = keyframes;
  for (auto _ : state) {
    Stopwatch watch;
    auto query = detector->add_keyframe(frame, test::pose_xy_yaw(10.0 * frame, 0, 0), q.edges, q.planes);
    samples.push_back(watch.elapsed_ms());
    benchmark::DoNotOptimize(query);
    ++frame;
  }
  const TimingStats s = summarize(samples);
  state.counters["p95_ms"] = s.p95;
  state.counters["max_ms"] = *std::max_element(samples.begin(), samples.end());
}
BENCHMARK(BM_QueryWithFeatureCloud)->Arg(1000)->Arg(5000)->Iterations(500)->Unit(benchmark::kMillisecond);

// The baseline's query: the same with the descriptor from the raw scan.
void BM_QueryWithRawScan(benchmark::State& state) {
  auto detector = filled_detector(static_cast<int>(state.range(0)));
  const auto& q = query_clouds();
  std::int64_t frame = state.range(0);
  for (auto _ : state) {
    benchmark::DoNotOptimize(detector->add_keyframe(frame, test::pose_xy_yaw(10.0 * frame, 0, 0), q.raw.points));
    ++frame;
  }
}
BENCHMARK(BM_QueryWithRawScan)->Arg(5000)->Iterations(200)->Unit(benchmark::kMillisecond);

// One k-d tree rebuild over 5000 ring keys (what a query pays every tree_rebuild_every keyframes).
void BM_RingKeyTreeRebuild(benchmark::State& state) {
  const auto& db = database(5000);
  for (auto _ : state) {
    state.PauseTiming();
    RingKeyIndex index(20, 5000);
    for (const auto& d : db) index.add(d.ring_key);
    state.ResumeTiming();
    benchmark::DoNotOptimize(index.nearest(db[0].ring_key, 10, db.size()));  // builds the tree
  }
}
BENCHMARK(BM_RingKeyTreeRebuild)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
