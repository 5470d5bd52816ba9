#include "eval/run_evaluation.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>

#include "common/dataset.h"
#include "common/estimate_io.h"
#include "common/setup.h"

namespace fs = std::filesystem;

namespace meshnav::eval {

namespace {

void note(RunEvaluation& ev, const std::string& msg) {
  spdlog::warn("{}", msg);
  ev.notes.push_back(msg);
}

}  // namespace

RunEvaluation evaluateRun(const std::string& dataset_dir, const std::string& run_dir,
                          const EvalOptions& options, const std::string& calibration_yaml) {
  RunEvaluation ev;
  Diagnostics diag;
  ev.dataset_dir = dataset_dir;
  ev.run_dir = run_dir;
  ev.options = options;
  const fs::path ds(dataset_dir), run(run_dir);

  // Ground truth trajectory.
  const fs::path gt_path = ds / "groundtruth.csv";
  if (!fs::exists(gt_path)) {
    note(ev, "no ground truth: " + gt_path.string() + " does not exist; pose metrics skipped");
  } else {
    try {
      ev.ground_truth = readTumCsv(gt_path.string(), diag);
      ev.has_ground_truth = ev.ground_truth.size() >= 2;
      if (!ev.has_ground_truth) note(ev, gt_path.string() + ": fewer than 2 valid poses; pose metrics skipped");
    } catch (const std::exception& ex) {
      note(ev, std::string("cannot read ground truth: ") + ex.what());
    }
  }

  // Setup (known anchors) and truth.
  std::map<SensorId, Eigen::Vector3d> known;
  const fs::path setup_path = ds / "setup.yaml";
  if (fs::exists(setup_path)) {
    try {
      // Exactly known anchors only: those given with a σ are estimated (refined online).
      const SystemSetup setup = loadSetup(setup_path.string());
      for (const auto& [id, p] : setup.abs_anchor_positions)
        if (!setup.abs_anchor_sigmas_m.count(id)) known[id] = p;
    } catch (const std::exception& ex) {
      note(ev, std::string("cannot read setup: ") + ex.what() + " (anchors are not marked known)");
    }
  }
  std::optional<Truth> truth;
  const fs::path truth_path = ds / "truth.yaml";
  if (!fs::exists(truth_path)) {
    note(ev, "no truth: " + truth_path.string() + " does not exist; anchor errors skipped");
  } else {
    try {
      truth = loadTruth(truth_path.string());
      ev.has_truth_yaml = true;
    } catch (const std::exception& ex) {
      note(ev, std::string("cannot read truth: ") + ex.what() + "; anchor errors skipped");
    }
  }

  // Flight state (only needed for the flying selection; used for flags anyway).
  std::vector<FlightStateSample> flight;
  const fs::path fs_path = ds / "flight_state.csv";
  if (fs::exists(fs_path)) {
    try {
      flight = readFlightStateCsv(fs_path.string(), diag);
      ev.has_flight_state = !flight.empty();
    } catch (const std::exception& ex) {
      note(ev, std::string("cannot read flight state: ") + ex.what());
    }
  }
  if (options.only_flying && !ev.has_flight_state)
    note(ev, "--only-flying: no flight_state.csv in the dataset; evaluating all samples");

  // Estimates.
  const fs::path est_path = run / "estimate.csv";
  if (!fs::exists(est_path)) {
    note(ev, "no estimate: " + est_path.string() + " does not exist; pose metrics skipped");
  } else {
    try {
      ev.estimates = readEstimateCsv(est_path.string(), diag);
      std::stable_sort(ev.estimates.begin(), ev.estimates.end(),
                       [](const PoseEstimate& a, const PoseEstimate& b) { return a.t < b.t; });
      if (ev.estimates.empty()) note(ev, est_path.string() + ": no valid estimate rows");
    } catch (const std::exception& ex) {
      note(ev, std::string("cannot read estimates: ") + ex.what());
    }
  }
  if (ev.has_ground_truth && !ev.estimates.empty()) {
    ev.errors = associate(ev.estimates, ev.ground_truth, flight, options, diag);
    if (ev.errors.empty())
      note(ev, "no estimate lies within the ground-truth time span (check that both use dataset seconds)");
  }
  EvalOptions eff = options;
  if (!ev.has_flight_state) eff.only_flying = false;
  ev.trajectory = computeTrajectoryMetrics(ev.errors, eff);
  if (eff.skip_first_s > 0.0 && ev.trajectory.n_selected == 0 && !ev.errors.empty())
    note(ev, "--skip " + std::to_string(eff.skip_first_s) + " s leaves no sample");

  // Anchors.
  const fs::path anchors_path = run / "anchors.csv";
  std::map<SensorId, AnchorEstimate> initial;
  std::string calib = calibration_yaml;
  if (calib.empty() && fs::exists(run / "calibration.yaml")) calib = (run / "calibration.yaml").string();
  if (!calib.empty()) {
    try {
      initial = readCalibrationYaml(calib);
    } catch (const std::exception& ex) {
      note(ev, std::string("cannot read calibration results: ") + ex.what() +
                   "; initial anchor beliefs are taken from anchors.csv");
    }
  }
  if (!fs::exists(anchors_path) && initial.empty()) {
    note(ev, "no anchor estimates: " + anchors_path.string() + " does not exist; anchor errors skipped");
  } else if (truth) {
    std::vector<AnchorEstimate> rows;
    if (fs::exists(anchors_path)) {
      try {
        rows = readAnchorsCsv(anchors_path.string(), diag);
      } catch (const std::exception& ex) {
        note(ev, std::string("cannot read anchor estimates: ") + ex.what());
      }
    }
    ev.anchors = computeAnchorMetrics(rows, truth->anchor_positions, known, initial, diag);
  }
  ev.diagnostics = diag.snapshot();
  return ev;
}

}  // namespace meshnav::eval
