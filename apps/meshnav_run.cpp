/// @file meshnav_run.cpp
/// @brief The whole pipeline in one process, deterministic and as fast as possible (README.md):
/// reads a dataset, merges every sample into time order, feeds the estimator node, writes
/// estimate.csv, anchors.csv, timings.csv and status.txt into --out. The estimator, calibrator and
/// mission nodes run in one `pipeline::Pipeline`, wired as the processes are over LCM. With
/// `--fleet FILE` several vehicles' datasets run in one pipeline that shares the anchor map.

#include <algorithm>
#include <spdlog/spdlog.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>

#include "common/atomic_file.h"
#include "common/cli_main.h"
#include "common/dataset.h"
#include "common/estimate_io.h"
#include "estimator/filter/strategy_factory.h"
#include "estimator/uwb/clock_offset_kind.h"
#include "estimator/node/estimator_input.h"
#include "estimator/node/estimator_node.h"
#include "calibrator/calibration_io.h"
#include "calibrator/node/calibrator_config.h"
#include "pipeline/anchor_belief_intersection.h"
#include "pipeline/fleet.h"
#include "pipeline/pipeline.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

constexpr char kDescription[] =
    "Runs the estimator, calibrator and mission nodes on a dataset folder in one process, in time order, as fast "
    "as possible (deterministic). Exit status 0: done; 1: an input or output file failed; 2: bad command line; "
    "3: the estimate ended lost or never initialized (--allow-lost: 0); 4: the UWB clock's delay ended more than "
    "5 sigma from its prior (setup.yaml uwb_clock); 5: the estimate ends more than 1 s before the vehicle's inputs "
    "(an IMU file that ends early, a refused tail); 6: the last re-initialization was never confirmed by the "
    "ranges after it (health ok for health.window_s with health.min_ranges ranges fitting; --allow-lost: 0); 130 / 143: stopped by SIGINT / SIGTERM, "
    "the rows and end-of-run files written so far (status.txt complete: false).";

/// The command line of meshnav_run.
struct RunOptions {
  std::string dataset, fleet, out, strategy, config, mission, calib_config;
  bool no_calibration = false, allow_lost = false, print_config = false, print_model_parameters = false;
  bool calibrate_on_smoothed = false;
  bool no_inter_vehicle_ranges = false;
  bool peer_truth = false;
};

void declareOptions(Cli& cli, RunOptions& o) {
  auto* dataset =
      cli.optional("dataset", o.dataset, "dataset folder (imu.csv, baro.csv, ranges.csv, flight_state.csv, setup.yaml)")
          ->type_name("DIR");
  cli.optional("fleet", o.fleet,
               "fleet file (YAML 'vehicles: [{name, dataset}]', docs/fleet.md): several vehicles sharing one anchor "
               "map, each with its own estimator, one calibrator for all; outputs in --out/NAME, calibration.yaml in "
               "--out")
      ->type_name("FILE")
      ->excludes(dataset);
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
  cli.flag("calibrate-on-smoothed", o.calibrate_on_smoothed,
           "the calibrator's tag poses become the fixed-lag smoothed ones as they come (fixed_lag.lag_s later; "
           "docs/smoother.md, calibration on the smoothed path)")
      ->excludes("--no-calibration");
  cli.flag("no-inter-vehicle-ranges", o.no_inter_vehicle_ranges,
           "with --fleet: count and drop the ranges between two vehicles' tags instead of fusing each in one of "
           "the two vehicles with the other's estimated tag (docs/fleet.md, inter-vehicle ranges)")
      ->needs("--fleet");
  cli.flag("peer-truth", o.peer_truth,
           "analysis only, with --fleet: fuse each inter-vehicle range in both vehicles with the other's TRUE tag "
           "(its dataset's groundtruth.csv) as an exact point: the bound of what the ranges allow (docs/fleet.md)")
      ->needs("--fleet")
      ->excludes("--no-inter-vehicle-ranges");
  cli.optional("calib-config", o.calib_config,
               "calibrator options YAML (default: built-in = config/calibrator.yaml); calibration results are "
               "written to calibration.yaml in --out")
      ->type_name("FILE");
  cli.flag("allow-lost", o.allow_lost, "exit 0 even if the estimate ends lost or never initialized (default: exit 3)");
  cli.flag("print-config", o.print_config, "print the estimator options (defaults or --config) as YAML and exit");
  cli.flag("print-model-parameters", o.print_model_parameters,
           "print the estimator's model parameters (fixed in code, not options; docs/configuration.md) and exit");
}

/// SIGINT or SIGTERM received (its number; 0: none): the run stops feeding, then writes its rows
/// and end-of-run files as at the end, and exits 128 + the signal (issue 36).
volatile std::sig_atomic_t g_signal = 0;

extern "C" void onStopSignal(int sig) { g_signal = sig; }

void writeTimings(const StepTimings& timings, const std::string& path) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "step,count,mean_us,median_us,max_us\n";
    for (const auto& [type, s] : timings.stats())
      out << type << ',' << s.count << ',' << s.mean_us << ',' << s.median_us << ',' << s.max_us << '\n';
  });
}

void writeStatus(const EstimatorStatus& st, double wall_s, double data_s, const std::string& path) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "complete: " << (g_signal ? "false  # interrupted by a signal" : "true") << "\n";
    out << "strategy: " << st.strategy << "\ninitialized: " << (st.initialized ? "true" : "false")
        << "\nhealth: " << st.health << "\nhealth_reason: \"" << st.health_reason << "\""
        << "\nsigma_p_max_m: " << st.sigma_p_max_m << "\nsigma_yaw_deg: " << st.sigma_yaw_deg
        << "\nuwb_clock_offset_s: " << st.uwb_clock_offset_s << "\nuwb_clock_offset_sigma_s: " << st.uwb_clock_offset_sigma_s
        << "\nfilter_time_s: " << formatSeconds(st.t) << "\nwall_time_s: " << wall_s << "\ndata_duration_s: " << data_s
        << "\nrealtime_factor: " << (wall_s > 0 ? data_s / wall_s : 0.0) << "\ncounters:\n";
    for (const auto& [k, v] : st.counters) out << "  " << k << ": " << v << '\n';
    out << "mean_step_us:\n";
    for (const auto& [k, v] : st.mean_step_us) out << "  " << k << ": " << v << '\n';
    out << "instances:\n";
    for (const auto& i : st.instances)
      out << "  - {id: " << i.id << ", type: " << i.type << ", n_updates: " << i.n_updates
          << ", n_rejected: " << i.n_rejected << "}\n";
  });
}

/// Feeds every input of `inputs` (time order, each to its vehicle) to the pipeline, with a progress line every 25 %,
/// until a stop signal. Returns the wall time it took [s].
double feed(pipeline::Pipeline& pipe, const std::vector<pipeline::FleetInput>& inputs, double data_s) {
  const Timestamp t_first = inputTime(inputs.front().input);
  const auto wall0 = std::chrono::steady_clock::now();
  int next_progress = 1;
  for (const auto& [vehicle, input] : inputs) {
    if (g_signal) {
      spdlog::warn("interrupted by signal {} at t = {} s ({:.0f} % of the data): writing what was estimated so far; "
                   "exit {}",
                   static_cast<int>(g_signal), formatSeconds(inputTime(input)),
                   data_s > 0 ? 100.0 * (inputTime(input) - t_first).sec() / data_s : 0.0, 128 + g_signal);
      break;
    }
    pipe.onInput(vehicle, input);
    if (data_s > 0 && (inputTime(input) - t_first).sec() >= next_progress * 0.25 * data_s) {
      spdlog::info("progress {:3d}% (t = {} s)", next_progress * 25, formatSeconds(inputTime(input)));
      ++next_progress;
    }
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
}

/// The UWB clock's delay a run may end with, in σ of its prior from the prior's mean [-]: beyond
/// it the prior was wrong (setup.yaml uwb_clock), and a delay that large is tracked only in part
/// (the range model is first order in it): a simulated 0.5 s ended at 239 ms (8σ of the default
/// prior), ATE 0.21 m against 0.10 m. Or the delay took up what the range model lacks: STAR-loc
/// with issue 34's range-error models off ends at 257 ms (ANEES 88). Every real recording and
/// widened-sweep run with the defaults ends within 2σ.
constexpr double kClockDelayBeyondPrior = 5.0;

/// How far before the vehicle's last input its estimate may end [s]: POSE follows the IMU, so an
/// IMU file that ends at 70 s of a 141 s flight ended the estimate at 70 s with exit 0 (issue 36).
/// A complete recording's streams end within a few IMU periods of each other; 1 s is ten times the
/// longest IMU interval the estimator takes without an `imu_gap` event (imu.max_dt_s, 0.1 s).
constexpr double kCoverageShortfall_s = 1.0;

/// The end-of-run log lines of one vehicle (`who`: "" or "vehicle NAME: "); returns its exit code
/// (3 when the estimate ends lost or never initialized, 4 when its UWB clock's delay ended beyond
/// kClockDelayBeyondPrior of its prior, 5 when its last POSE, `last_pose`, is more than
/// kCoverageShortfall_s before `last_input`, the vehicle's newest input).
int report(const EstimatorNode& node, const SystemSetup& setup, double data_s, double wall_s, const std::string& out_dir,
           bool allow_lost, const std::string& who, std::optional<Timestamp> last_pose, Timestamp last_input) {
  const EstimatorStatus st = node.status();
  if (!node.initialized()) spdlog::error("{}the estimator never initialized: {}", who, node.waitingFor());
  if (auto pose = node.pose())
    spdlog::info("{}final: p_IinG [{:.3f}, {:.3f}, {:.3f}] m, b_gyro [{:.5f}, {:.5f}, {:.5f}] rad/s, "
                 "b_acc [{:.4f}, {:.4f}, {:.4f}] m/s^2, IMU noise scale {:.3g}",
                 who, pose->p_IinG.x(), pose->p_IinG.y(), pose->p_IinG.z(), pose->bias_gyro_rad_s.x(),
                 pose->bias_gyro_rad_s.y(), pose->bias_gyro_rad_s.z(), pose->bias_acc_m_s2.x(),
                 pose->bias_acc_m_s2.y(), pose->bias_acc_m_s2.z(), node.processNoiseScale());
  if (node.initialized())
    spdlog::info("{}UWB clock: stamps {:.1f} ms late against the IMU ({})", who, st.uwb_clock_offset_s * 1e3,
                 st.uwb_clock_offset_sigma_s > 0 ? fmt::format("estimated, σ {:.1f} ms", st.uwb_clock_offset_sigma_s * 1e3)
                                                  : std::string("setup.yaml's constant"));
  std::string counters;
  for (const auto& [k, v] : st.counters) counters += fmt::format("{}={} ", k, v);
  spdlog::info("{}counters: {}", who, counters);
  for (const auto& [type, s] : node.timings().stats())
    spdlog::info("{}step {:<13} n={:<7} mean {:8.2f} us  median {:8.2f} us  max {:8.1f} us", who, type, s.count,
                 s.mean_us, s.median_us, s.max_us);
  spdlog::info("{}processed {:.1f} s of data in {:.3f} s wall (real-time factor {:.0f}x); results in {}", who, data_s,
               wall_s, wall_s > 0 ? data_s / wall_s : 0.0, out_dir);
  // A run that ends lost (no usable aiding, or runaway the recovery could not fix) is not healthy.
  const int64_t lost_events = st.counters.count("health_lost") ? st.counters.at("health_lost") : 0;
  if (node.initialized() && node.health() == Health::Lost)
    spdlog::error("{}the estimate ends LOST ({}); {} lost events, {} recoveries", who, st.health_reason, lost_events,
                  st.counters.count("recovery") ? st.counters.at("recovery") : 0);
  else if (lost_events > 0 && !node.unconfirmedRecovery())
    spdlog::warn("{}the estimate was lost {} times during the run and recovered", who, lost_events);
  const bool healthy = node.initialized() && node.health() != Health::Lost;
  if (!(healthy || allow_lost)) return 3;
  // A re-initialization is a recovery only once the ranges after it back it (issue 36: one ended
  // 1.18 km off after "lost 1 times during the run and recovered", exit 0).
  if (const auto rec = node.unconfirmedRecovery(); healthy && rec) {
    spdlog::error("{}the estimate was re-initialized at t={} s and the ranges since never confirmed it (health ok "
                  "for {:.1f} s at the end; confirmed takes {:.1f} s of health ok with {} tag ranges accepted at a mean "
                  "NIS within {:.1f}): the estimate since then is not to be trusted{}",
                  who, formatSeconds(rec->first), rec->second, node.options().health.window_s,
                  node.options().health.min_ranges, node.options().health.degraded_mean_nis,
                  allow_lost ? " (--allow-lost: exit 0)" : "; exit 6");
    if (!allow_lost) return 6;
  }
  // The delay's departure from its prior (issue 36: IMU stamps 0.5 s off the ranges passed silently).
  const double prior_sigma_s = ClockOffsetKind::priorSigma(setup, node.options());
  if (node.initialized() && st.uwb_clock_offset_sigma_s > 0.0 && prior_sigma_s > 0.0 &&
      std::abs(st.uwb_clock_offset_s - setup.uwb_clock.offset_s) > kClockDelayBeyondPrior * prior_sigma_s) {
    spdlog::error("{}the UWB clock's delay ended at {:.0f} ms, {:.1f} sigma from its prior ({:.0f} +- {:.0f} ms): "
                  "either the stamps of the IMU and the ranges are that far apart (state it in setup.yaml "
                  "uwb_clock.offset_s) or the delay took up an error the range model lacks; the estimate is not to "
                  "be trusted (docs/uwb_bias_model.md, \"Clock offset\"); exit 4",
                  who, st.uwb_clock_offset_s * 1e3,
                  std::abs(st.uwb_clock_offset_s - setup.uwb_clock.offset_s) / prior_sigma_s,
                  setup.uwb_clock.offset_s * 1e3, prior_sigma_s * 1e3);
    return 4;
  }
  // Coverage (issue 36: an IMU file ending at half the flight ended the estimate there, exit 0).
  // POSE follows the IMU: the filter may still fuse ranges after the IMU's end, but nothing is written.
  if (last_pose && (last_input - *last_pose).sec() > kCoverageShortfall_s) {
    spdlog::error("{}the estimate ends at {} s, {:.1f} s before the last input at {} s: the IMU ended early or the "
                  "inputs after it were refused (counters above); the rest of the recording has no estimate; exit 5",
                  who, formatSeconds(*last_pose), (last_input - *last_pose).sec(), formatSeconds(last_input));
    return 5;
  }
  return 0;
}

/// One vehicle of the run: its dataset, its output folder and its writers.
struct VehicleRun {
  std::string name;  ///< "" for a single dataset
  std::string dataset;
  std::filesystem::path out;
  Dataset ds;
  std::unique_ptr<EstimateCsvWriter> estimates;
  std::unique_ptr<AnchorsCsvWriter> anchors;
  std::unique_ptr<EstimateCsvWriter> smoothed;  ///< fixed-lag smoothed poses (fixed_lag.enabled)
  std::string who() const { return name.empty() ? "" : "vehicle " + name + ": "; }
};

/// The vehicles of the run: --dataset (one, writing into --out) or the --fleet file's (each into
/// --out/NAME). Reads every dataset.
std::vector<VehicleRun> readVehicles(const RunOptions& o) {
  std::vector<VehicleRun> runs;
  if (!o.fleet.empty()) {
    for (const auto& e : pipeline::loadFleetFile(o.fleet)) {
      VehicleRun r;
      r.name = e.name;
      r.dataset = e.dataset;
      r.out = std::filesystem::path(o.out) / e.name;
      runs.push_back(std::move(r));
    }
  } else {
    VehicleRun r;
    r.dataset = o.dataset;
    r.out = o.out;
    runs.push_back(std::move(r));
  }
  for (auto& r : runs) {
    Diagnostics diag;
    spdlog::info("{}reading dataset {}", r.who(), r.dataset);
    r.ds = readDataset(r.dataset, diag, false);
    spdlog::info("{}dataset: {} imu, {} baro, {} ranges, {} flight states, {} heights{}", r.who(), r.ds.imu.size(),
                 r.ds.baro.size(), r.ds.ranges.size(), r.ds.flight_states.size(), r.ds.heights.size(),
                 diag.total() ? "; dropped/flagged: " + diag.summary() : "");
  }
  return runs;
}

/// A fleet's datasets must be stamped by one clock: their time spans must overlap.
void checkSharedClock(const std::vector<VehicleRun>& runs, const std::vector<std::vector<EstimatorInput>>& inputs,
                      const std::string& fleet_file) {
  Timestamp latest_start = inputTime(inputs[0].front()), earliest_end = inputTime(inputs[0].back());
  std::string spans;
  for (size_t v = 0; v < runs.size(); ++v) {
    const Timestamp a = inputTime(inputs[v].front()), b = inputTime(inputs[v].back());
    latest_start = std::max(latest_start, a);
    earliest_end = std::min(earliest_end, b);
    spans += fmt::format("{}{} {}-{} s", v ? ", " : "", runs[v].name, formatSeconds(a), formatSeconds(b));
  }
  if (latest_start > earliest_end)
    throw std::runtime_error(fleet_file + ": the vehicles' datasets share no time span (" + spans +
                             "); a fleet's recordings must be stamped by one clock");
}

/// The whole run: datasets in, pipeline, files out. Returns the exit code.
int runPipeline(const RunOptions& o, const EstimatorOptions& options) {
  pipeline::PipelineOptions popts;
  popts.estimator = options;
  popts.calibration_enabled = !o.no_calibration;
  popts.calibrator_on_smoothed = o.calibrate_on_smoothed;
  popts.inter_vehicle_ranges = !o.no_inter_vehicle_ranges;
  calib::CalibratorConfig calib_config = calib::CalibratorConfig::load(o.calib_config);
  if (!o.mission.empty()) popts.mission = mission::loadMission(o.mission);

  std::vector<VehicleRun> runs = readVehicles(o);
  std::vector<pipeline::Vehicle> vehicles;
  for (const auto& r : runs) vehicles.push_back({r.name, r.ds.setup});
  const SystemSetup fleet_setup = o.fleet.empty() ? runs[0].ds.setup : pipeline::mergeFleetSetups(vehicles, o.fleet);
  if (o.peer_truth) {
    for (const auto& r : runs)
      if (r.ds.ground_truth.empty())
        throw std::runtime_error(r.dataset + ": --peer-truth needs groundtruth.csv");
    popts.peer_truth = [&runs](size_t v, Timestamp t) -> std::optional<PoseSample> {
      const std::vector<PoseSample>& gt = runs.at(v).ds.ground_truth;
      auto it = std::lower_bound(gt.begin(), gt.end(), t, [](const PoseSample& p, Timestamp x) { return p.t < x; });
      if (it == gt.end() || it == gt.begin()) return std::nullopt;  // outside the ground truth
      const PoseSample& b = *it;
      const PoseSample& a = *std::prev(it);
      const double w = (t - a.t).sec() / std::max((b.t - a.t).sec(), 1e-9);
      PoseSample p;
      p.t = t;
      p.p_IinG = (1.0 - w) * a.p_IinG + w * b.p_IinG;
      p.q_ItoG = a.q_ItoG.slerp(w, b.q_ItoG);
      return p;
    };
  }

  std::vector<std::vector<EstimatorInput>> per_vehicle;
  for (size_t v = 0; v < runs.size(); ++v) {
    per_vehicle.push_back(mergeInTimeOrder(runs[v].ds));
    if (per_vehicle.back().empty()) throw std::runtime_error(runs[v].dataset + ": no samples");
  }
  if (runs.size() > 1) checkSharedClock(runs, per_vehicle, o.fleet);
  const std::vector<pipeline::FleetInput> inputs = pipeline::mergeFleetInputs(per_vehicle);

  for (auto& r : runs) {
    std::filesystem::create_directories(r.out);
    // A smoother's output of an earlier run in this folder belongs to that run: meshnav_eval would
    // score it beside this one (docs/smoother.md).
    // (estimate_smoothed.csv is this run's fixed-lag smoother's, fixed_lag.enabled.)
    for (const char* stale : {"estimate_smoothed.csv", "anchors_smoothed.csv", "smoother.yaml", "errors_smoothed.csv"})
      if ((!options.fixed_lag.enabled() || std::string(stale) != "estimate_smoothed.csv") &&
          std::filesystem::remove(r.out / stale))
        spdlog::info("removed {} of an earlier run (meshnav smooth it again)", (r.out / stale).string());
    r.estimates = std::make_unique<EstimateCsvWriter>((r.out / "estimate.csv").string());
    if (options.fixed_lag.enabled())
      r.smoothed = std::make_unique<EstimateCsvWriter>((r.out / "estimate_smoothed.csv").string());
    r.anchors = std::make_unique<AnchorsCsvWriter>((r.out / "anchors.csv").string());
  }
  // The calibrator's range σ_d comes from setup.yaml (the first vehicle's in a fleet) unless the
  // calibrator config sets it, as in the calibrator process.
  calib_config.applySetup(fleet_setup);
  popts.calibrator = calib_config.calibrator;
  popts.calibrator_node = calib_config.node;
  pipeline::PipelineSinks psinks;
  std::vector<std::optional<Timestamp>> last_pose(runs.size());  // each vehicle's newest POSE written
  psinks.pose = [&](size_t v, const PoseEstimate& e) {
    runs[v].estimates->write(e);
    last_pose[v] = std::max(last_pose[v].value_or(e.t), e.t);
  };
  if (options.fixed_lag.enabled())
    psinks.pose_smoothed = [&](size_t v, const PoseEstimate& e) { runs[v].smoothed->write(e); };
  psinks.anchors = [&](size_t v, const std::vector<AnchorEstimate>& list) {
    for (const auto& a : list) runs[v].anchors->write(a);
  };
  pipeline::Pipeline pipe(popts, vehicles, fleet_setup, psinks);
  spdlog::info("estimator options:\n{}", pipe.estimator().options().toString());
  spdlog::info("calibration: {}{}", !popts.calibration_enabled ? "off (known anchors only)"
                                    : popts.mission            ? "by mission " + o.mission
                                                               : std::string("automatic"),
               runs.size() > 1 ? fmt::format(", one anchor map for {} vehicles", runs.size()) : std::string());

  const double data_s = (inputTime(inputs.back().input) - inputTime(inputs.front().input)).sec();
  std::signal(SIGINT, onStopSignal);
  std::signal(SIGTERM, onStopSignal);
  const double wall_s = feed(pipe, inputs, data_s);
  int code = 0;
  // The end of the stream: what waits for an IMU sample, a re-run still on its worker (before the
  // final anchors), the last lag_s of smoothed poses.
  pipe.finish();
  for (size_t v = 0; v < runs.size(); ++v) {
    EstimatorNode& node = pipe.estimator(v);
    if (node.initialized())
      for (const auto& a : node.anchors()) runs[v].anchors->write(a);
    runs[v].estimates->flush();
    runs[v].anchors->flush();
    if (runs[v].smoothed) runs[v].smoothed->flush();
    writeTimings(node.timings(), (runs[v].out / "timings.csv").string());
  }
  if (runs.size() > 1) {
    // The fleet's one belief of each estimated anchor: the covariance intersection of every
    // vehicle's final belief (they share the calibration: docs/decisions/016-fleet-sharing.md).
    std::vector<std::vector<AnchorEstimate>> per_vehicle(runs.size());
    for (size_t v = 0; v < runs.size(); ++v)
      if (pipe.estimator(v).initialized()) per_vehicle[v] = pipe.estimator(v).anchors();
    AnchorsCsvWriter shared((std::filesystem::path(o.out) / "shared_anchors.csv").string());
    for (const AnchorEstimate& a : pipeline::AnchorBeliefIntersection::fuseVehicles(per_vehicle)) shared.write(a);
    shared.flush();
  }
  if (pipe.diagnostics().total() > 0) spdlog::info("fleet: {}", pipe.diagnostics().summary());
  if (const auto* cal = pipe.calibrator()) {
    const std::filesystem::path calib_file = std::filesystem::path(o.out) / "calibration.yaml";
    calib::writeCalibrationYaml(cal->results(), calib_file.string());
    std::string ids;
    for (const auto& a : pipe.anchorInits()) ids += (ids.empty() ? "" : ",") + std::to_string(a.id);
    spdlog::info("calibration: {} anchors initialized ({}), results in {}", pipe.anchorInits().size(),
                 ids.empty() ? std::string("none") : ids, calib_file.string());
    // The anchors left out, each with why (a refusal, or what automatic calibration waits for).
    for (const auto& a : cal->status().anchors)
      if (a.state != "calibrated")
        spdlog::warn("calibration: anchor {} not calibrated ({}, {} ranges from {} references){}", a.id, a.state,
                     a.n_ranges, a.n_refs, a.reason.empty() ? std::string() : ": " + a.reason);
  }
  for (size_t v = 0; v < runs.size(); ++v) {
    const EstimatorNode& node = pipe.estimator(v);
    writeStatus(node.status(), wall_s, data_s, (runs[v].out / "status.txt").string());
    code = std::max(code, report(node, runs[v].ds.setup, data_s, wall_s, runs[v].out.string(), o.allow_lost,
                                 runs[v].who(), last_pose[v], inputTime(per_vehicle[v].back())));
  }
  return g_signal ? 128 + g_signal : code;
}

/// The work of main: --print-config, or the pipeline on --dataset.
int run(const RunOptions& o) {
  EstimatorOptions options = o.config.empty() ? EstimatorOptions{} : EstimatorOptions::fromYaml(o.config);
  if (o.print_config) {
    std::cout << options.toString();
    return 0;
  }
  if (o.print_model_parameters) {
    std::cout << options.modelParametersString();
    return 0;
  }
  if ((o.dataset.empty() && o.fleet.empty()) || o.out.empty()) {
    std::cerr << "meshnav_run: --dataset (or --fleet) and --out are required (see --help)\n";
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