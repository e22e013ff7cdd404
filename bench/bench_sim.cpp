// Simulator speed: one HDL-64E sweep in the loops city, and building that city.
//   build*/bin/bench_sim [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include "scfloam/sim/scan.hpp"
#include "scfloam/sim/scenario.hpp"

namespace {
using namespace scfloam::sim;

const Scenario& city() {
  static const Scenario sc = make_loops_scenario(1, 1000);
  return sc;
}

void BM_RenderSweep(benchmark::State& state, const char* sensor_name) {
  const Scenario& sc = city();
  const SensorModel sensor = sensor_preset(sensor_name);
  const BeamCalibration calib = draw_beam_calibration(sensor, 1);
  std::size_t frame = 0, points = 0;
  for (auto _ : state) {
    SweepPoses poses;
    poses.T_world_lidar = sc.frame_pose(frame % sc.frames);
    const auto scan = render_scan(sc.world, sensor, calib, poses, 1, frame);
    points += scan.points.size();
    frame += 37;
  }
  state.counters["points_per_scan"] = static_cast<double>(points) / state.iterations();
}
BENCHMARK_CAPTURE(BM_RenderSweep, hdl64, "hdl64")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RenderSweep, vlp16, "vlp16")->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_BuildLoopsCity(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(make_loops_scenario(2, 1000).world.primitives.size());
}
BENCHMARK(BM_BuildLoopsCity)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
