// Pose graph optimization cost: 2000 keyframes with 50 loops (issue 5's target: <= 100 ms).
// A 250-keyframe circuit (2 m apart) driven 8 times with noisy, biased odometry; loops join
// keyframes one lap apart.
#include <benchmark/benchmark.h>

#include <random>

#include "scfloam/backend/pose_graph.hpp"
#include "scfloam/se3.hpp"

using namespace scfloam;

namespace {

struct Scenario {
  PoseList truth, odometry;
  std::vector<std::pair<std::size_t, std::size_t>> loops;  // (current, earlier)
};

Scenario make_scenario(std::size_t keyframes, std::size_t loops) {
  const std::size_t lap = 250;
  Scenario s;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.linear() = so3_exp(Eigen::Vector3d(0, 0, 2 * M_PI / lap));
  step.translation() = Eigen::Vector3d(2.0, 0, 0);
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity(), odom = truth;
  for (std::size_t i = 0; i < keyframes; ++i) {
    s.truth.push_back(truth);
    s.odometry.push_back(odom);
    Eigen::Matrix<double, 6, 1> err;
    err << 2e-4 * noise(rng), 2e-4 * noise(rng), 3e-4 + 2e-4 * noise(rng), 0.01 * noise(rng),
        0.01 * noise(rng), 0.005 * noise(rng);
    truth = truth * step;
    odom = odom * left_perturb(err, step);
  }
  const std::size_t stride = (keyframes - lap) / loops;
  for (std::size_t k = 0; k < loops; ++k) {
    const std::size_t current = lap + k * stride + stride / 2;
    s.loops.push_back({current, current - lap});
  }
  return s;
}

PoseGraph build_graph(const Scenario& s, std::size_t loops, const PoseGraphConfig& config) {
  PoseGraph graph;
  for (const auto& T : s.odometry) graph.add_node(T);
  for (std::size_t i = 1; i < s.odometry.size(); ++i)
    graph.add_odometry_edge(i - 1, i, s.odometry[i - 1].inverse() * s.odometry[i], config);
  for (std::size_t k = 0; k < loops; ++k) {
    const auto [cur, old] = s.loops[k];
    graph.add_loop_edge(cur, old, s.truth[cur].inverse() * s.truth[old], config);
  }
  return graph;
}

// The whole graph solved from the odometry initial guess.
void BM_PoseGraphFromScratch(benchmark::State& state) {
  const Scenario s = make_scenario(2000, 50);
  PoseGraphConfig config;
  for (auto _ : state) {
    state.PauseTiming();
    PoseGraph graph = build_graph(s, 50, config);
    state.ResumeTiming();
    const PoseGraphReport r = graph.optimize(config);
    state.counters["iterations"] = r.iterations;
  }
}
BENCHMARK(BM_PoseGraphFromScratch)->Unit(benchmark::kMillisecond);

// What the pipeline pays per accepted loop: 49 loops already solved, the 50th arrives.
void BM_PoseGraphAddOneLoop(benchmark::State& state) {
  const Scenario s = make_scenario(2000, 50);
  PoseGraphConfig config;
  for (auto _ : state) {
    state.PauseTiming();
    PoseGraph graph = build_graph(s, 49, config);
    graph.optimize(config);
    const auto [cur, old] = s.loops[49];
    graph.add_loop_edge(cur, old, s.truth[cur].inverse() * s.truth[old], config);
    state.ResumeTiming();
    const PoseGraphReport r = graph.optimize(config);
    state.counters["iterations"] = r.iterations;
  }
}
BENCHMARK(BM_PoseGraphAddOneLoop)->Unit(benchmark::kMillisecond);

// Issue 5's question at 5000 keyframes (125 loops, the 125th arrives): the whole graph
// re-solved from the previous solution, against a bounded window that starts at the new
// loop's older keyframe (everything before it held fixed). Arg: 0 whole graph, 1 window.
void BM_PoseGraph5000AddOneLoop(benchmark::State& state) {
  const std::size_t loops = 125;
  const Scenario s = make_scenario(5000, loops);
  PoseGraphConfig config;
  const bool window = state.range(0) == 1;
  for (auto _ : state) {
    state.PauseTiming();
    PoseGraph graph = build_graph(s, loops - 1, config);
    graph.optimize(config);
    const auto [cur, old] = s.loops[loops - 1];
    graph.add_loop_edge(cur, old, s.truth[cur].inverse() * s.truth[old], config);
    state.ResumeTiming();
    const PoseGraphReport r = graph.optimize(config, window ? old : 0);
    state.counters["iterations"] = r.iterations;
    state.PauseTiming();
    // Accuracy of the result: mean keyframe position error against the truth.
    double error_m = 0;
    for (std::size_t i = 0; i < s.truth.size(); ++i)
      error_m += (graph.pose(i).translation() - s.truth[i].translation()).norm();
    state.counters["mean_error_m"] = error_m / s.truth.size();
    state.ResumeTiming();
  }
}
BENCHMARK(BM_PoseGraph5000AddOneLoop)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
