/// @file meshnav_run.cpp
/// @brief The whole pipeline in one process, deterministic and as fast as possible (DESIGN §8):
/// reads a dataset, merges every sample into time order, feeds the estimator node, writes
/// estimate.csv, anchors.csv, timings.csv and status.txt into --out. The estimator, calibrator and
/// mission nodes run in one `pipeline::Pipeline`, wired as the processes are over LCM.

#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "common/cli.h"
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

const char* kUsage = R"(meshnav_run — run the estimator on a dataset folder, as fast as possible.

Usage: meshnav_run --dataset DIR --out DIR [--strategy centralized|dp|dah] [--config FILE]
                   [--mission FILE | --no-calibration] [--calib-config FILE]

  --dataset DIR    dataset folder (imu.csv, baro.csv, ranges.csv, flight_state.csv, setup.yaml)
  --out DIR        output folder (created): estimate.csv, anchors.csv, timings.csv, status.txt
  --strategy S     fusion strategy: centralized (dense EKF), dp (modular, centralized-equivalent),
                   dah (modular, updates only the involved instances); default: the config's
  --config FILE    estimator options YAML (default: built-in defaults = config/estimator.yaml)
  --mission FILE   mission script (YAML steps: collect / calibrate anchors at dataset times,
                   e.g. config/missions/paper_s2.yaml); without one, new anchors are collected
                   and calibrated automatically once their data suffices
  --no-calibration known anchors only: ranges to unknown anchors are ignored (and counted)
  --calib-config FILE  calibrator options YAML (default: built-in = config/calibrator.yaml);
                   calibration results are written to calibration.yaml in --out
  --allow-lost     exit 0 even if the estimate ends lost or never initialized (default: exit 3)
  --print-config   print the estimator options (defaults or --config) as YAML and exit
  --help           this text
)";

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

}  // namespace

int main(int argc, char** argv) {
  setupLogging("meshnav_run");
  Cli cli("meshnav_run", kUsage);
  cli.option("dataset").option("out").option("strategy").option("config").option("mission");
  cli.option("no-calibration", false).option("calib-config");
  cli.option("print-config", false).option("allow-lost", false);
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  if (cli.has("print-config")) {
    try {
      std::cout << (cli.has("config") ? EstimatorOptions::fromYaml(cli.get("config")) : EstimatorOptions{}).toString();
      return 0;
    } catch (const std::exception& e) {
      std::cerr << "meshnav_run: " << e.what() << "\n";
      return 1;
    }
  }
  if (!cli.has("dataset") || !cli.has("out")) {
    std::cerr << "meshnav_run: --dataset and --out are required\n\n" << kUsage;
    return 2;
  }
  std::string strategy = cli.get("strategy", "");
  if (strategy.empty()) {
    try {
      strategy = cli.has("config") ? EstimatorOptions::fromYaml(cli.get("config")).strategy : EstimatorOptions{}.strategy;
    } catch (const std::exception& e) {
      std::cerr << "meshnav_run: " << e.what() << "\n";
      return 1;
    }
  }
  if (!strategyImplemented(strategy)) {
    std::cerr << "meshnav_run: unknown strategy '" << strategy << "'\n\n" << kUsage;
    return 2;
  }
  try {
    EstimatorOptions options;
    if (cli.has("config")) options = EstimatorOptions::fromYaml(cli.get("config"));
    options.strategy = strategy;
    if (cli.has("mission") && cli.has("no-calibration")) {
      std::cerr << "meshnav_run: --mission and --no-calibration exclude each other\n";
      return 2;
    }
    pipeline::PipelineOptions popts;
    popts.estimator = options;
    popts.calibration_enabled = !cli.has("no-calibration");
    calib::CalibratorConfig calib_config = calib::CalibratorConfig::load(cli.get("calib-config", ""));
    if (cli.has("mission")) popts.mission = mission::loadMission(cli.get("mission"));

    Diagnostics diag;
    const std::string dir = cli.get("dataset");
    spdlog::info("reading dataset {}", dir);
    const Dataset ds = readDataset(dir, diag, false);
    spdlog::info("dataset: {} imu, {} baro, {} ranges, {} flight states{}", ds.imu.size(), ds.baro.size(),
                 ds.ranges.size(), ds.flight_states.size(),
                 diag.total() ? "; dropped/flagged: " + diag.summary() : "");

    const std::filesystem::path out_dir = cli.get("out");
    std::filesystem::create_directories(out_dir);
    EstimateCsvWriter est_writer((out_dir / "estimate.csv").string());
    AnchorsCsvWriter anchor_writer((out_dir / "anchors.csv").string());
    EstimatorSinks sinks;
    sinks.pose = [&](const PoseEstimate& e) { est_writer.write(e); };
    sinks.anchors = [&](const std::vector<AnchorEstimate>& v) {
      for (const auto& a : v) anchor_writer.write(a);
    };
    // The calibrator's range σ_d comes from setup.yaml unless the calibrator config sets it, as in
    // the calibrator process.
    calib_config.applySetup(ds.setup);
    popts.calibrator = calib_config.calibrator;
    popts.calibrator_node = calib_config.node;
    pipeline::PipelineSinks psinks;
    psinks.pose = sinks.pose;
    psinks.anchors = sinks.anchors;
    pipeline::Pipeline pipe(popts, ds.setup, psinks);
    EstimatorNode& node = pipe.estimator();
    spdlog::info("estimator options:\n{}", node.options().toString());
    spdlog::info("calibration: {}", !popts.calibration_enabled ? "off (known anchors only)"
                                    : popts.mission ? "by mission " + cli.get("mission")
                                                    : std::string("automatic"));

    const std::vector<EstimatorInput> inputs = mergeInTimeOrder(ds);
    if (inputs.empty()) throw std::runtime_error(dir + ": no samples");
    const Timestamp t_first = inputTime(inputs.front()), t_last = inputTime(inputs.back());
    const double data_s = (t_last - t_first).sec();
    const auto wall0 = std::chrono::steady_clock::now();
    int next_progress = 1;
    for (size_t i = 0; i < inputs.size(); ++i) {
      pipe.onInput(inputs[i]);
      if (data_s > 0 && (inputTime(inputs[i]) - t_first).sec() >= next_progress * 0.25 * data_s) {
        spdlog::info("progress {:3d}% (t = {} s)", next_progress * 25, formatSeconds(inputTime(inputs[i])));
        ++next_progress;
      }
    }
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    if (node.initialized())
      for (const auto& a : node.anchors()) anchor_writer.write(a);
    est_writer.flush();
    anchor_writer.flush();
    writeTimings(node.timings(), (out_dir / "timings.csv").string());
    if (const auto* cal = pipe.calibrator()) {
      calib::writeCalibrationYaml(cal->results(), (out_dir / "calibration.yaml").string());
      spdlog::info("calibration: {} anchors initialized ({}), results in calibration.yaml", pipe.anchorInits().size(),
                   [&] {
                     std::string ids;
                     for (const auto& a : pipe.anchorInits()) ids += (ids.empty() ? "" : ",") + std::to_string(a.id);
                     return ids.empty() ? std::string("none") : ids;
                   }());
    }
    const EstimatorStatus st = node.status();
    writeStatus(st, wall_s, data_s, (out_dir / "status.txt").string());

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
                 wall_s, wall_s > 0 ? data_s / wall_s : 0.0, out_dir.string());
    // A run that ends lost (no usable aiding, or runaway the recovery could not fix) is not healthy.
    const int64_t lost_events = st.counters.count("health_lost") ? st.counters.at("health_lost") : 0;
    if (node.initialized() && node.health() == Health::Lost)
      spdlog::error("the estimate ends LOST ({}); {} lost events, {} recoveries", st.health_reason, lost_events,
                    st.counters.count("recovery") ? st.counters.at("recovery") : 0);
    else if (lost_events > 0)
      spdlog::warn("the estimate was lost {} times during the run and recovered", lost_events);
    const bool healthy = node.initialized() && node.health() != Health::Lost;
    if (healthy || cli.has("allow-lost")) return 0;
    return 3;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
