/// @file bench_pipeline.cpp
/// @brief Google Benchmark of the whole in-process pipeline as `meshnav run` runs it, I/O included
/// (`./meshnav bench pipeline`; issue 38's speed target, docs/results.md "Speed").
///
/// Paper sequence 1 (meshnav_sim --seed 1, 140 s, IMU 200 Hz, ranges of two tags to 101–110) is
/// simulated once and written as a dataset folder into a temporary folder. Every iteration then
/// does what meshnav_run does between its command line and its end-of-run report: reads the
/// dataset (readDataset), merges it in time order, runs the estimator, calibrator and mission
/// nodes in one `pipeline::Pipeline` with the estimator's defaults (centralized, the fixed-lag
/// smoother on) and streams estimate.csv, estimate_smoothed.csv and anchors.csv to disk. Cases:
///  - RunPaperSequence/auto: fly-by calibration without a mission (meshnav_run's default): the
///    calibrator initializes 106–110 once their data suffices, each join re-runs the history;
///  - RunPaperSequence/mission_s2: fly-by calibration by config/missions/paper_s2.yaml (106, 107
///    at 80 s, 108–110 at 100 s);
///  - RunPaperSequence/no_calibration: known anchors only (`--no-calibration`);
///  - the same two without the fixed-lag smoother (`fixed_lag.lag_s: 0`), `*_no_smoother`: the
///    filter alone, the floor of this design;
///  - IoOnly: only what a run reads and writes (the dataset read and merged in time order, one
///    estimate.csv and one estimate_smoothed.csv row per IMU sample, as the run writes them): the
///    floor of any estimator behind `meshnav run`'s files.
/// Counters: realtime_factor = data seconds per second of the benchmark's time (CPU time of the
/// thread by default; `--benchmark_min_time` and repetitions as usual), data_s, poses (rows of
/// estimate.csv), anchor_joins, reruns.

#include <benchmark/benchmark.h>
#include <spdlog/spdlog.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "calibrator/node/calibrator_config.h"
#include "common/dataset.h"
#include "common/estimate_io.h"
#include "estimator/node/estimator_input.h"
#include "mission/mission.h"
#include "pipeline/pipeline.h"
#include "sim/scenario_simulator.h"

using namespace meshnav;

namespace {

/// The simulated paper sequence 1, written once into a temporary folder (removed at exit).
const std::filesystem::path& datasetDir() {
  static const std::filesystem::path dir = [] {
    char tmpl[] = "/tmp/meshnav_bench_pipeline_XXXXXX";
    const char* made = mkdtemp(tmpl);
    if (!made) throw std::runtime_error("bench_pipeline: mkdtemp failed");
    const std::filesystem::path d(made);
    sim::SimulationOptions so;
    so.seed = 1;
    writeDataset(sim::ScenarioSimulator(so).run().dataset, (d / "dataset").string());
    std::atexit([] { std::filesystem::remove_all(datasetDir()); });
    return d;
  }();
  return dir;
}

enum class Calibration { Auto, MissionS2, Off };

void RunPaperSequence(benchmark::State& state, Calibration calibration, bool smoother) {
  const std::filesystem::path root = datasetDir();
  const std::string dataset = (root / "dataset").string();
  const std::filesystem::path out = root / "run";
  std::filesystem::create_directories(out);
  double data_s = 0.0;
  int64_t poses = 0, joins = 0, reruns = 0;
  for (auto _ : state) {
    Diagnostics diag;
    const Dataset ds = readDataset(dataset, diag, false);
    const std::vector<estimator::EstimatorInput> inputs = estimator::mergeInTimeOrder(ds);
    pipeline::PipelineOptions popts;
    if (!smoother) popts.estimator.fixed_lag.lag_s = 0.0;
    popts.calibration_enabled = calibration != Calibration::Off;
    if (calibration == Calibration::MissionS2)
      popts.mission = mission::loadMission(MESHNAV_SOURCE_DIR "/config/missions/paper_s2.yaml");
    calib::CalibratorConfig cc = calib::CalibratorConfig::load("");
    cc.applySetup(ds.setup);
    popts.calibrator = cc.calibrator;
    popts.calibrator_node = cc.node;
    EstimateCsvWriter estimates((out / "estimate.csv").string());
    EstimateCsvWriter smoothed((out / "estimate_smoothed.csv").string());
    AnchorsCsvWriter anchors((out / "anchors.csv").string());
    pipeline::PipelineSinks sinks;
    poses = 0;
    sinks.pose = [&](size_t, const PoseEstimate& e) {
      estimates.write(e);
      ++poses;
    };
    if (popts.estimator.fixed_lag.enabled())
      sinks.pose_smoothed = [&](size_t, const PoseEstimate& e) { smoothed.write(e); };
    sinks.anchors = [&](size_t, const std::vector<AnchorEstimate>& list) {
      for (const auto& a : list) anchors.write(a);
    };
    pipeline::Pipeline pipe(popts, ds.setup, sinks);
    for (const auto& in : inputs) pipe.onInput(in);
    pipe.finish();
    if (pipe.estimator().initialized())
      for (const auto& a : pipe.estimator().anchors()) anchors.write(a);
    estimates.flush();
    smoothed.flush();
    anchors.flush();
    data_s = (estimator::inputTime(inputs.back()) - estimator::inputTime(inputs.front())).sec();
    joins = static_cast<int64_t>(pipe.anchorInits().size());
    const auto counters = pipe.estimator().status().counters;
    reruns = counters.count("rerun") ? counters.at("rerun") : 0;
  }
  state.counters["realtime_factor"] =
      benchmark::Counter(data_s * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["data_s"] = data_s;
  state.counters["poses"] = static_cast<double>(poses);
  state.counters["anchor_joins"] = static_cast<double>(joins);
  state.counters["reruns"] = static_cast<double>(reruns);
}

void IoOnly(benchmark::State& state) {
  const std::filesystem::path root = datasetDir();
  const std::string dataset = (root / "dataset").string();
  const std::filesystem::path out = root / "io_only";
  std::filesystem::create_directories(out);
  double data_s = 0.0;
  int64_t poses = 0;
  for (auto _ : state) {
    Diagnostics diag;
    const Dataset ds = readDataset(dataset, diag, false);
    const std::vector<estimator::EstimatorInput> inputs = estimator::mergeInTimeOrder(ds);
    EstimateCsvWriter estimates((out / "estimate.csv").string());
    EstimateCsvWriter smoothed((out / "estimate_smoothed.csv").string());
    PoseEstimate e;
    e.p_IinG = {1.234567, -2.345678, 3.456789};
    e.v_IinG = {0.123456, 0.234567, -0.345678};
    e.cov_p_m2 = e.cov_v = e.cov_theta_rad2 = 1e-3 * Eigen::Matrix3d::Identity();
    poses = 0;
    for (const auto& in : inputs) {
      if (!std::holds_alternative<ImuSample>(in)) continue;
      e.t = estimator::inputTime(in);
      estimates.write(e);
      smoothed.write(e);
      ++poses;
    }
    estimates.flush();
    smoothed.flush();
    data_s = (estimator::inputTime(inputs.back()) - estimator::inputTime(inputs.front())).sec();
  }
  state.counters["realtime_factor"] =
      benchmark::Counter(data_s * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["data_s"] = data_s;
  state.counters["poses"] = static_cast<double>(poses);
}

}  // namespace

BENCHMARK_CAPTURE(RunPaperSequence, auto, Calibration::Auto, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(RunPaperSequence, mission_s2, Calibration::MissionS2, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(RunPaperSequence, no_calibration, Calibration::Off, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(RunPaperSequence, auto_no_smoother, Calibration::Auto, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(RunPaperSequence, no_calibration_no_smoother, Calibration::Off, false)->Unit(benchmark::kMillisecond);
BENCHMARK(IoOnly)->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  spdlog::set_level(spdlog::level::err);  // the dataset's unknown-device warnings are expected
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
