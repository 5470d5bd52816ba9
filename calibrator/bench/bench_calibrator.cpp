/// Google Benchmark of the anchor calibration: whole calibration, linear step and RANSAC on a
/// synthetic spiral flight with ranges to tags 100/105 and known anchors 101–104
/// (σ_d = 0.1 m, 10 % outliers). 700 ranges ≈ a 1 Hz mesh over 60 s; 7000 = 10×.
#include <benchmark/benchmark.h>

#include <map>

#include "calibrator/anchor_calibrator.h"
#include "calibrator/calibration_problem.h"
#include "calibrator/optimal_double_solver.h"
#include "calibrator/ransac_solver.h"
#include "calibrator/synthetic_scene.h"

using namespace meshnav::calib;

namespace {

const SyntheticScene& scene(int n) {
  static std::map<int, SyntheticScene> cache;
  auto it = cache.find(n);
  if (it == cache.end()) {
    SyntheticSceneConfig cfg;
    cfg.n_ranges = n;
    cfg.outlier_fraction = 0.10;
    cfg.seed = 7;
    it = cache.emplace(n, makeSyntheticScene(cfg)).first;
  }
  return it->second;
}

void Calibrate(benchmark::State& st) {
  const auto& sc = scene(static_cast<int>(st.range(0)));
  const AnchorCalibrator cal(CalibratorOptions{});
  for (auto _ : st) {
    auto r = cal.calibrate(106, sc.observations);
    benchmark::DoNotOptimize(r.p_AinG);
    if (!r.ok()) st.SkipWithError("calibration refused");
  }
}

void CalibrateNoRansac(benchmark::State& st) {
  const auto& sc = scene(static_cast<int>(st.range(0)));
  CalibratorOptions o;
  o.ransac = false;
  const AnchorCalibrator cal(o);
  for (auto _ : st) {
    auto r = cal.calibrate(106, sc.observations);
    benchmark::DoNotOptimize(r.p_AinG);
  }
}

void LinearStep(benchmark::State& st) {
  const auto& sc = scene(static_cast<int>(st.range(0)));
  const CalibratorOptions o;
  const CalibrationProblem pb(106, sc.observations, {}, o);
  const OptimalDoubleSolver solver(o);
  for (auto _ : st) {
    auto s = solver.solve(pb);
    benchmark::DoNotOptimize(s.params.p_AinG);
  }
}

void Ransac(benchmark::State& st) {
  const auto& sc = scene(static_cast<int>(st.range(0)));
  const CalibratorOptions o;
  const CalibrationProblem pb(106, sc.observations, {}, o);
  const RansacSolver ransac(o);
  int iters = 0;
  for (auto _ : st) {
    auto r = ransac.run(pb, 1);
    iters = r.iterations;
    benchmark::DoNotOptimize(r.solution.params.p_AinG);
  }
  st.counters["iterations"] = iters;
}

}  // namespace

BENCHMARK(Calibrate)->ArgName("ranges")->Arg(700)->Arg(7000)->Unit(benchmark::kMillisecond);
BENCHMARK(CalibrateNoRansac)->ArgName("ranges")->Arg(700)->Arg(7000)->Unit(benchmark::kMillisecond);
BENCHMARK(LinearStep)->ArgName("ranges")->Arg(700)->Arg(7000)->Unit(benchmark::kMillisecond);
BENCHMARK(Ransac)->ArgName("ranges")->Arg(700)->Arg(7000)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
