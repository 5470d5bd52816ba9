/// @file meshnav_run.cpp
/// @brief The whole pipeline in one process, deterministic and as fast as possible (README.md):
/// reads a dataset, merges every sample into time order, feeds the estimator node, writes
/// estimate.csv, anchors.csv, timings.csv and status.txt into --out. The estimator, calibrator and
/// mission nodes run in one `pipeline::Pipeline`, wired as the processes are over LCM.

#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "common/cli_main.h"
#include "common/dataset.h"
#include "common/estimate_io.h"
#include "estimator/filter/strategy_factory.h"
#include "estimator/node/estimator_input.h"
#include "estimator/node/estimator_node.h"
#include "calibrator/calibration_io.h"
#include "calibrator/node/calibrator_config.h"
#include "pipeline/pipeline.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

constexpr char kDescription[] =
    "Runs the estimator, calibrator and mission nodes on a dataset folder in one process, in time order, as fast "
    "as possible (deterministic).";

/// The command line of meshnav_run.
struct RunOptions {
  std::string dataset, out, strategy, config, mission, calib_config;
  bool no_calibration = false, allow_lost = false, print_config = false;
};

void declareOptions(Cli& cli, RunOptions& o) {
  cli.optional("dataset", o.dataset, "dataset folder (imu.csv, baro.csv, ranges.csv, flight_state.csv, setup.yaml)")
      ->type_name("DIR");
  cli.optional("out", o.out, "output folder (created): estimate.csv, anchors.csv, timings.csv, status.txt")
      ->type_name("DIR");
  cli.optional("strategy", o.strategy,
               "fusion strategy: " + strategySummaries() + "; default: the config's")
      ->check(cli::oneOf(strategyListed, strategyNames()));
  cli.optional("config", o.config, "estimator options YAML (default: built-in defaults = config/estimator.yaml)")
      ->type_name("FILE");
  auto* mission = cli.optional("mission", o.mission,
                               "mission script (YAML steps: collect / calibrate anchors at dataset times, e.g. "
                               "config/missions/paper_s2.yaml); without one, new anchors are collected and "
                               "calibrated automatically once their data suffices")
                      ->type_name("FILE");
  cli.flag("no-calibration", o.no_calibration, "known anchors only: ranges to unknown anchors are ignored (and counted)")
      ->excludes(mission);
  cli.optional("calib-config", o.calib_config,
               "calibrator options YAML (default: built-in = config/calibrator.yaml); calibration results are "
               "written to calibration.yaml in --out")
      ->type_name("FILE");
  cli.flag("allow-lost", o.allow_lost, "exit 0 even if the estimate ends lost or never initialized (default: exit 3)");
  cli.flag("print-config", o.print_config, "print the estimator options (defaults or --config) as YAML and exit");
}

void writeTimings(const StepTimings& timings, const std::string& path) {
  std::ofstream out(path);
  out << "step,count,mean_us,median_us,max_us\n";
  for (const auto& [type, s] : timings.stats())
    out << type << ',' << s.count << ',' << s.mean_us << ',' << s.median_us << ',' << s.max_us << '\n';
}

void writeStatus(const EstimatorStatus& st, double wall_s, double data_s, const std::string& path) {
  std::ofstream out(path);
  out << "strategy: " << st.strategy << "\ninitialized: " << (st.initialized ? "true" : "false")
      << "\nhealth: " << st.health << "\nhealth_reason: \"" << st.health_reason << "\""
      << "\nsigma_p_max_m: " << st.sigma_p_max_m << "\nsigma_yaw_deg: " << st.sigma_yaw_deg
      << "\nfilter_time_s: " << formatSeconds(st.t) << "\nwall_time_s: " << wall_s << "\ndata_duration_s: " << data_s
      << "\nrealtime_factor: " << (wall_s > 0 ? data_s / wall_s : 0.0) << "\ncounters:\n";
  for (const auto& [k, v] : st.counters) out << "  " << k << ": " << v << '\n';
  out << "mean_step_us:\n";
  for (const auto& [k, v] : st.mean_step_us) out << "  " << k << ": " << v << '\n';
  out << "instances:\n";
  for (const auto& i : st.instances)
    out << "  - {id: " << i.id << ", type: " << i.type << ", n_updates: " << i.n_updates
        << ", n_rejected: " << i.n_rejected << "}\n";
}

/// Feeds every input of `inputs` (time order) to the pipeline, with a progress line every 25 %.
/// Returns the wall time it took [s].
double feed(pipeline::Pipeline& pipe, const std::vector<EstimatorInput>& inputs, double data_s) {
  const Timestamp t_first = inputTime(inputs.front());
  const auto wall0 = std::chrono::steady_clock::now();
  int next_progress = 1;
  for (const auto& input : inputs) {
    pipe.onInput(input);
    if (data_s > 0 && (inputTime(input) - t_first).sec() >= next_progress * 0.25 * data_s) {
      spdlog::info("progress {:3d}% (t = {} s)", next_progress * 25, formatSeconds(inputTime(input)));
      ++next_progress;
    }
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
}

/// The end-of-run log lines; returns the exit code (3 when the estimate ends lost or never initialized).
int report(const EstimatorNode& node, double data_s, double wall_s, const std::string& out_dir, bool allow_lost) {
  const EstimatorStatus st = node.status();
  if (!node.initialized()) spdlog::error("the estimator never initialized: {}", node.waitingFor());
  if (auto pose = node.pose())
    spdlog::info("final: p_IinG [{:.3f}, {:.3f}, {:.3f}] m, b_gyro [{:.5f}, {:.5f}, {:.5f}] rad/s, "
                 "b_acc [{:.4f}, {:.4f}, {:.4f}] m/s^2, IMU noise scale {:.3g}",
                 pose->p_IinG.x(), pose->p_IinG.y(), pose->p_IinG.z(), pose->bias_gyro_rad_s.x(),
                 pose->bias_gyro_rad_s.y(), pose->bias_gyro_rad_s.z(), pose->bias_acc_m_s2.x(),
                 pose->bias_acc_m_s2.y(), pose->bias_acc_m_s2.z(), node.processNoiseScale());
  std::string counters;
  for (const auto& [k, v] : st.counters) counters += fmt::format("{}={} ", k, v);
  spdlog::info("counters: {}", counters);
  for (const auto& [type, s] : node.timings().stats())
    spdlog::info("step {:<13} n={:<7} mean {:8.2f} us  median {:8.2f} us  max {:8.1f} us", type, s.count, s.mean_us,
                 s.median_us, s.max_us);
  spdlog::info("processed {:.1f} s of data in {:.3f} s wall (real-time factor {:.0f}x); results in {}", data_s,
               wall_s, wall_s > 0 ? data_s / wall_s : 0.0, out_dir);
  // A run that ends lost (no usable aiding, or runaway the recovery could not fix) is not healthy.
  const int64_t lost_events = st.counters.count("health_lost") ? st.counters.at("health_lost") : 0;
  if (node.initialized() && node.health() == Health::Lost)
    spdlog::error("the estimate ends LOST ({}); {} lost events, {} recoveries", st.health_reason, lost_events,
                  st.counters.count("recovery") ? st.counters.at("recovery") : 0);
  else if (lost_events > 0)
    spdlog::warn("the estimate was lost {} times during the run and recovered", lost_events);
  const bool healthy = node.initialized() && node.health() != Health::Lost;
  return healthy || allow_lost ? 0 : 3;
}

/// The whole run: dataset in, pipeline, files out. Returns the exit code.
int runPipeline(const RunOptions& o, const EstimatorOptions& options) {
  pipeline::PipelineOptions popts;
  popts.estimator = options;
  popts.calibration_enabled = !o.no_calibration;
  calib::CalibratorConfig calib_config = calib::CalibratorConfig::load(o.calib_config);
  if (!o.mission.empty()) popts.mission = mission::loadMission(o.mission);

  Diagnostics diag;
  spdlog::info("reading dataset {}", o.dataset);
  const Dataset ds = readDataset(o.dataset, diag, false);
  spdlog::info("dataset: {} imu, {} baro, {} ranges, {} flight states, {} heights{}", ds.imu.size(), ds.baro.size(),
               ds.ranges.size(), ds.flight_states.size(), ds.heights.size(), diag.total() ? "; dropped/flagged: " + diag.summary() : "");

  const std::filesystem::path out_dir = o.out;
  std::filesystem::create_directories(out_dir);
  EstimateCsvWriter est_writer((out_dir / "estimate.csv").string());
  AnchorsCsvWriter anchor_writer((out_dir / "anchors.csv").string());
  // The calibrator's range σ_d comes from setup.yaml unless the calibrator config sets it, as in
  // the calibrator process.
  calib_config.applySetup(ds.setup);
  popts.calibrator = calib_config.calibrator;
  popts.calibrator_node = calib_config.node;
  pipeline::PipelineSinks psinks;
  psinks.pose = [&](const PoseEstimate& e) { est_writer.write(e); };
  psinks.anchors = [&](const std::vector<AnchorEstimate>& v) {
    for (const auto& a : v) anchor_writer.write(a);
  };
  pipeline::Pipeline pipe(popts, ds.setup, psinks);
  EstimatorNode& node = pipe.estimator();
  spdlog::info("estimator options:\n{}", node.options().toString());
  spdlog::info("calibration: {}", !popts.calibration_enabled ? "off (known anchors only)"
                                  : popts.mission            ? "by mission " + o.mission
                                                             : std::string("automatic"));

  const std::vector<EstimatorInput> inputs = mergeInTimeOrder(ds);
  if (inputs.empty()) throw std::runtime_error(o.dataset + ": no samples");
  const double data_s = (inputTime(inputs.back()) - inputTime(inputs.front())).sec();
  const double wall_s = feed(pipe, inputs, data_s);
  node.finishRerun();  // refine.rerun_mode async: a re-run still on its worker comes in before the final anchors
  if (node.initialized())
    for (const auto& a : node.anchors()) anchor_writer.write(a);
  est_writer.flush();
  anchor_writer.flush();
  writeTimings(node.timings(), (out_dir / "timings.csv").string());
  if (const auto* cal = pipe.calibrator()) {
    calib::writeCalibrationYaml(cal->results(), (out_dir / "calibration.yaml").string());
    std::string ids;
    for (const auto& a : pipe.anchorInits()) ids += (ids.empty() ? "" : ",") + std::to_string(a.id);
    spdlog::info("calibration: {} anchors initialized ({}), results in calibration.yaml", pipe.anchorInits().size(),
                 ids.empty() ? std::string("none") : ids);
    // The anchors left out, each with why (a refusal, or what automatic calibration waits for).
    for (const auto& a : cal->status().anchors)
      if (a.state != "calibrated")
        spdlog::warn("calibration: anchor {} not calibrated ({}, {} ranges from {} references){}", a.id, a.state,
                     a.n_ranges, a.n_refs, a.reason.empty() ? std::string() : ": " + a.reason);
  }
  writeStatus(node.status(), wall_s, data_s, (out_dir / "status.txt").string());
  return report(node, data_s, wall_s, out_dir.string(), o.allow_lost);
}

/// The work of main: --print-config, or the pipeline on --dataset.
int run(const RunOptions& o) {
  EstimatorOptions options = o.config.empty() ? EstimatorOptions{} : EstimatorOptions::fromYaml(o.config);
  if (o.print_config) {
    std::cout << options.toString();
    return 0;
  }
  if (o.dataset.empty() || o.out.empty()) {
    std::cerr << "meshnav_run: --dataset and --out are required (see --help)\n";
    return 2;
  }
  if (!o.strategy.empty()) options.strategy = o.strategy;
  return runPipeline(o, options);
}

}  // namespace

int main(int argc, char** argv) {
  return cliMain<RunOptions>(argc, argv, "meshnav_run", kDescription, declareOptions,
                             [](const Cli&, RunOptions& o) { return run(o); });
}