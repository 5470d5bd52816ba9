/// @file bench_estimator.cpp
/// @brief Google Benchmark of the estimator. Names follow `<Step>/<strategy>/<anchors>` with
/// <anchors> the number of estimated (3-state) anchors besides the exact ones:
///  - Propagate/centralized/N: one 5 ms IMU propagation (nominal + covariance);
///  - RangeUpdate/centralized/N: one tag–anchor range update (linearize + EKF update);
///  - Sequence/centralized/N: a whole synthetic 140 s sequence through EstimatorNode (as fast as
///    possible; counter `realtime_factor`).

#include <benchmark/benchmark.h>
#include <spdlog/spdlog.h>

#include "estimator/filter/strategy_factory.h"
#include "estimator/node/estimator_node.h"
#include "estimator/testing/synthetic_scenario.h"
#include "estimator/uwb/range_model.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

constexpr int kAnchorCounts[] = {0, 5, 9, 20};

/// A filter with the IMU, the baro and `n` estimated anchors, correlated by a few updates.
std::unique_ptr<FusionStrategy> makeFilter(int n, UwbNetwork& net) {
  synthetic::SyntheticOptions so;
  so.n_estimated_anchors = n;
  const SystemSetup setup = synthetic::syntheticSetup(so);
  net = UwbNetwork(setup, 0.1);
  auto f = makeStrategy(EstimatorOptions{});
  ImuState x;
  x.p_IinG = {0.5, 0.5, 2.0};
  f->reset(setup.imu_id, x, ImuMatrix::Identity() * 0.01, Timestamp{});
  f->addBaro(setup.baro_id, 0.0, 0.25);
  for (const auto& [id, sigma] : setup.abs_anchor_sigmas_m)
    f->addAnchor(id, setup.abs_anchor_positions.at(id), Eigen::Matrix3d::Identity() * sigma * sigma);
  for (const auto& [id, p] : setup.abs_anchor_positions) {
    Linearization lin;
    RangeMeasurement z{Timestamp{}, 100, id, (p - x.p_IinG).norm(), 0.01};
    if (RangeModel::linearize(z, f->state(), net, &lin) == RangeModel::Status::Ok) f->update(lin, 0.0);
  }
  return f;
}

void Propagate(benchmark::State& state, int n) {
  UwbNetwork net;
  auto f = makeFilter(n, net);
  const Eigen::Vector3d acc(0.1, -0.2, 9.81), gyro(0.01, 0.02, 0.1);
  Timestamp t = f->state().t;
  for (auto _ : state) {
    t = t + Duration::fromMs(5);
    f->propagate(acc, gyro, t);
    benchmark::DoNotOptimize(f->state().imu.p_IinG.data());
  }
  state.counters["state_dim"] = f->layout().dim();
}

void RangeUpdate(benchmark::State& state, int n) {
  UwbNetwork net;
  auto f = makeFilter(n, net);
  const SensorId anchor = n > 0 ? 106 : 101;
  const Eigen::Vector3d p_A = n > 0 ? f->state().anchor_p_AinG.at(anchor) : *net.exactAnchor(anchor);
  for (auto _ : state) {
    // Keep the covariance from collapsing over millions of iterations.
    state.PauseTiming();
    auto g = f->clone();
    state.ResumeTiming();
    const double d = (p_A - g->state().imu.p_IinG).norm();
    RangeMeasurement z{Timestamp{}, 100, anchor, d + 0.05, 0.01};
    Linearization lin;
    RangeModel::linearize(z, g->state(), net, &lin);
    benchmark::DoNotOptimize(g->update(lin, 0.0));
  }
  state.counters["state_dim"] = f->layout().dim();
}

void Sequence(benchmark::State& state, int n) {
  synthetic::SyntheticOptions so;
  so.duration_s = 140.0;
  so.noise = true;
  so.n_estimated_anchors = n;
  const Dataset ds = synthetic::makeSyntheticDataset(so);
  const auto inputs = mergeInTimeOrder(ds);
  for (auto _ : state) {
    EstimatorNode node(EstimatorOptions{}, ds.setup);
    for (const auto& in : inputs) node.onInput(in);
    benchmark::DoNotOptimize(node.pose());
  }
  state.counters["inputs"] = static_cast<double>(inputs.size());
  state.counters["realtime_factor"] =
      benchmark::Counter(so.duration_s * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void registerAll() {
  for (int n : kAnchorCounts) {
    const std::string s = std::to_string(n);
    benchmark::RegisterBenchmark(("Propagate/centralized/" + s).c_str(), Propagate, n);
    benchmark::RegisterBenchmark(("RangeUpdate/centralized/" + s).c_str(), RangeUpdate, n);
  }
  for (int n : {0, 5})
    benchmark::RegisterBenchmark(("Sequence/centralized/" + std::to_string(n)).c_str(), Sequence, n)
        ->Unit(benchmark::kMillisecond);
}

}  // namespace

int main(int argc, char** argv) {
  spdlog::set_level(spdlog::level::warn);
  registerAll();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
