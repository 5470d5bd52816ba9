/// Google Benchmark of the scaled fleet's simulation (meshnav_sim --vehicles, docs/scenarios.md
/// "A hundred anchors in TDMA cells"): 5 vehicles among 100 anchors in a 40 x 40 x 10 m hall over
/// a 140 s flight: IMU, baro, ground truth and the cell ranges (no file writing).
/// Argument: the flight's length [s].
#include <benchmark/benchmark.h>

#include "sim/scaled_fleet_simulation.h"

using namespace meshnav::sim;

namespace {

void SimulateScaledFleet(benchmark::State& st) {
  ScaledFleetOptions o;
  o.base.seed = 1;
  o.base.duration_s = static_cast<double>(st.range(0));
  for (auto _ : st) {
    const meshnav::sim::ScaledFleet f = simulateScaledFleet(o);
    benchmark::DoNotOptimize(f.vehicles.back().dataset.ranges.size());
  }
}
BENCHMARK(SimulateScaledFleet)->Arg(140)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
