/// @file bench_smoother.cpp
/// @brief Cost of the smoother (Google Benchmark; `./meshnav bench smoother`): the preintegration of
/// one knot span, and the whole-recording smoother on the analytic scenario (estimator/testing:
/// two tags, four anchors, 200 Hz IMU, noisy) of 30 s and 60 s, from the truth perturbed as a
/// filter's poses are (0.1 m, 2°). Per second of data: the 30 s and 60 s cases in one run.

#include <benchmark/benchmark.h>

#include <cmath>

#include "estimator/testing/synthetic_scenario.h"
#include "smoother/run_smoother.h"
#include "smoother/testing/perturbed_run.h"

using namespace meshnav;
using namespace meshnav::smoother;
namespace syn = meshnav::estimator::synthetic;

namespace {

Dataset scenario(double duration_s) {
  syn::SyntheticOptions o;
  o.duration_s = duration_s;
  o.pair_rate_hz = 5.0;
  o.anchor_to_anchor = false;
  o.noise = true;
  return syn::makeSyntheticDataset(o);
}

void Preintegrate(benchmark::State& state) {
  const Dataset ds = scenario(5.0);
  for (auto _ : state) {
    auto inc = preintegrate(ds.imu, Timestamp::fromSec(1.0), Timestamp::fromSec(1.1), Eigen::Vector3d::Zero(),
                            Eigen::Vector3d::Zero(), ImuNoiseDensities{});
    benchmark::DoNotOptimize(inc);
  }
}

void SmoothRun(benchmark::State& state) {
  const double duration_s = static_cast<double>(state.range(0));
  const Dataset ds = scenario(duration_s);
  const FilterRun run = testing::perturbedRun(ds, 0.1, 2.0);
  for (auto _ : state) {
    auto sm = smoothRun(ds, run, RunSmootherOptions{});
    benchmark::DoNotOptimize(sm);
  }
  state.counters["data_s"] = duration_s;
}

}  // namespace

BENCHMARK(Preintegrate)->Unit(benchmark::kMicrosecond);
BENCHMARK(SmoothRun)->Arg(30)->Arg(60)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_MAIN();
