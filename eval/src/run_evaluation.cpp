#include "eval/run_evaluation.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>

#include "common/dataset.h"
#include "common/estimate_io.h"
#include "common/setup.h"
#include "eval/truth_consistency.h"

namespace fs = std::filesystem;

namespace meshnav::eval {

namespace {

void note(RunEvaluation& ev, const std::string& msg) {
  spdlog::warn("{}", msg);
  ev.notes.push_back(msg);
}

/// groundtruth.csv of the dataset (at least 2 poses for pose metrics).
void readGroundTruth(RunEvaluation& ev, const fs::path& ds, Diagnostics& diag) {
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
}

/// Drops the truth where it contradicts the gyro of imu.csv (a motion-capture dropout): each such
/// window is noted and counted ("eval:truth_gyro_mismatch"), its estimates are then not scored.
void checkTruthWithGyro(RunEvaluation& ev, const fs::path& ds, Diagnostics& diag) {
  const fs::path imu_path = ds / "imu.csv";
  if (!ev.options.check_truth_with_gyro || !ev.has_ground_truth || !fs::exists(imu_path)) return;
  std::vector<ImuSample> imu;
  try {
    Diagnostics imu_diag;  // the estimator reports imu.csv's rows; here they only serve the check
    imu = readImuCsv(imu_path.string(), imu_diag);
  } catch (const std::exception& ex) {
    note(ev, std::string("truth check against the gyro skipped: ") + ex.what());
    return;
  }
  const std::vector<TruthFault> faults = truthGyroFaults(ev.ground_truth, imu);
  if (faults.empty()) return;
  diag.count("eval:truth_gyro_mismatch", static_cast<int64_t>(faults.size()));
  std::string where;
  for (size_t k = 0; k < faults.size() && k < 5; ++k)
    where += (k ? ", " : "") + formatSeconds(faults[k].t0) + "–" + formatSeconds(faults[k].t1) + " s (truth " +
             std::to_string(faults[k].truth_angle_rad).substr(0, 5) + ", gyro " +
             std::to_string(faults[k].gyro_angle_rad).substr(0, 5) + " rad)";
  const size_t dropped = dropTruthInFaults(ev.ground_truth, faults);
  note(ev, "ground truth contradicts the gyro of imu.csv in " + std::to_string(faults.size()) + " stretch(es): " + where +
               (faults.size() > 5 ? ", ..." : "") + "; its " + std::to_string(dropped) +
               " poses there are left out (--no-truth-check keeps them; eval/truth_consistency.h)");
  ev.has_ground_truth = ev.ground_truth.size() >= 2;
}

/// Drops the truth in the windows of --exclude (noted, counted "eval:excluded_truth_pose").
void excludeWindows(RunEvaluation& ev, Diagnostics& diag) {
  if (ev.options.exclude_windows_s.empty() || !ev.has_ground_truth) return;
  std::vector<TruthFault> windows;
  std::string where;
  for (const auto& [t0, t1] : ev.options.exclude_windows_s) {
    TruthFault w;
    w.t0 = Timestamp::fromSec(t0);
    w.t1 = Timestamp::fromSec(t1);
    windows.push_back(w);
    where += (where.empty() ? "" : ", ") + formatSeconds(w.t0) + "–" + formatSeconds(w.t1) + " s";
  }
  size_t dropped = 0;
  for (const TruthFault& w : windows) {
    const size_t n = dropTruthInFaults(ev.ground_truth, {w});
    if (n == 0)  // most likely seconds from the start given where the files hold Unix stamps
      note(ev, "--exclude " + formatSeconds(w.t0) + "–" + formatSeconds(w.t1) +
                   " s holds no ground-truth pose: the window is in the files' stamps (dataset time)");
    dropped += n;
  }
  diag.count("eval:excluded_truth_pose", static_cast<int64_t>(dropped));
  note(ev, "--exclude " + where + ": " + std::to_string(dropped) + " ground-truth poses left out (their estimates "
           "enter neither the alignment nor the figures)");
  ev.has_ground_truth = ev.ground_truth.size() >= 2;
  if (!ev.has_ground_truth) note(ev, "fewer than 2 ground-truth poses outside --exclude; pose metrics skipped");
}

/// The alignment of the estimate: --align if given, else se3 when truth.yaml says the ground truth
/// is in another frame, else none.
void chooseAlignment(RunEvaluation& ev, const std::optional<Truth>& truth) {
  if (ev.options.align) {
    ev.alignment = *ev.options.align;
    ev.alignment_reason = "--align " + toString(ev.alignment);
  } else if (truth && truth->align_required) {
    ev.alignment = AlignmentMode::Se3;
    ev.alignment_reason = "default: truth.yaml says groundtruth.csv is in frame '" + truth->truth_frame +
                          "' (align_required), so the estimate is aligned (se3, Umeyama without scale)";
  } else {
    ev.alignment = AlignmentMode::None;
    ev.alignment_reason = "default: ground truth in the estimate's frame (truth.yaml has no align_required)";
  }
}

/// Multilateration of the dataset's ranges with the same alignment and selection.
void runBaseline(RunEvaluation& ev, const fs::path& ds, const std::optional<SystemSetup>& setup,
                 const std::vector<FlightStateSample>& flight, Diagnostics& diag) {
  if (!ev.options.baseline || !ev.has_ground_truth) return;
  if (!setup) {
    note(ev, "multilateration baseline skipped: no readable setup.yaml");
    return;
  }
  try {
    Diagnostics range_diag;
    const auto ranges = readRangesCsv((ds / "ranges.csv").string(), range_diag);
    ev.baseline = evaluateBaseline(ranges, *setup, ev.ground_truth, flight, ev.alignment, ev.options, diag);
    for (const auto& n : ev.baseline->notes) note(ev, n);
  } catch (const std::exception& ex) {
    note(ev, std::string("multilateration baseline skipped: ") + ex.what());
  }
}

/// Reads the run's estimate.csv, sorted by time (nothing when no run folder is given).
void runEstimates(RunEvaluation& ev, const fs::path& run, Diagnostics& diag) {
  const fs::path est_path = run / "estimate.csv";
  if (ev.run_dir.empty()) {
    note(ev, "no run given: only the multilateration baseline is evaluated");
  } else if (!fs::exists(est_path)) {
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
}

/// Anchor errors of the run's anchors.csv (and calibration results) against truth.yaml.
void evaluateAnchors(RunEvaluation& ev, const fs::path& run, const std::string& calibration_yaml,
                     const std::optional<Truth>& truth, const std::map<SensorId, Eigen::Vector3d>& known,
                     Diagnostics& diag) {
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

  readGroundTruth(ev, ds, diag);
  checkTruthWithGyro(ev, ds, diag);
  excludeWindows(ev, diag);

  // Setup (known anchors) and truth.
  std::map<SensorId, Eigen::Vector3d> known;
  std::optional<SystemSetup> setup;
  const fs::path setup_path = ds / "setup.yaml";
  if (fs::exists(setup_path)) {
    try {
      // Exactly known anchors only: those given with a σ are estimated (refined online).
      setup = loadSetup(setup_path.string());
      for (const auto& [id, p] : setup->abs_anchor_positions)
        if (!setup->abs_anchor_sigmas_m.count(id)) known[id] = p;
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
  chooseAlignment(ev, truth);

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

  runBaseline(ev, ds, setup, flight, diag);

  runEstimates(ev, run, diag);
  if (ev.has_ground_truth && !ev.estimates.empty()) {
    ev.alignment_transform = alignToGroundTruth(ev.estimates, ev.ground_truth, ev.alignment, options.max_gt_gap_s);
    if (!ev.alignment_transform) note(ev, "alignment " + toString(ev.alignment) + " could not be fitted; estimate not aligned");
    ev.errors = associate(ev.estimates, ev.ground_truth, flight, options, diag);
    if (ev.errors.empty())
      note(ev, "no estimate lies within the ground-truth time span (check that both use dataset seconds)");
  }
  EvalOptions eff = options;
  if (!ev.has_flight_state) eff.only_flying = false;
  ev.trajectory = computeTrajectoryMetrics(ev.errors, eff);
  if (eff.skip_first_s > 0.0 && ev.trajectory.n_selected == 0 && !ev.errors.empty())
    note(ev, "--skip " + std::to_string(eff.skip_first_s) + " s leaves no sample");

  if (!run_dir.empty() && ev.has_ground_truth && fs::exists(run / "estimate_smoothed.csv")) {
    try {
      SmoothedEvaluation sm;
      sm.estimates = readEstimateCsv((run / "estimate_smoothed.csv").string(), diag);
      std::stable_sort(sm.estimates.begin(), sm.estimates.end(),
                       [](const PoseEstimate& a, const PoseEstimate& b) { return a.t < b.t; });
      if (!sm.estimates.empty()) {
        sm.alignment_transform = alignToGroundTruth(sm.estimates, ev.ground_truth, ev.alignment, options.max_gt_gap_s);
        sm.errors = associate(sm.estimates, ev.ground_truth, flight, options, diag);
        sm.trajectory = computeTrajectoryMetrics(sm.errors, eff);
        ev.smoothed = std::move(sm);
      } else {
        note(ev, (run / "estimate_smoothed.csv").string() + ": no valid rows");
      }
    } catch (const std::exception& ex) {
      note(ev, std::string("cannot read the smoothed estimate: ") + ex.what());
    }
  }
  if (!run_dir.empty()) evaluateAnchors(ev, run, calibration_yaml, truth, known, diag);
  ev.diagnostics = diag.snapshot();
  return ev;
}

int64_t skippedTimeRows(const RunEvaluation& ev) {
  static const std::string kSuffix = ":bad_time";
  int64_t n = 0;
  for (const auto& [key, count] : ev.diagnostics)
    if (key.size() > kSuffix.size() && key.compare(key.size() - kSuffix.size(), kSuffix.size(), kSuffix) == 0)
      n += count;
  return n;
}

}  // namespace meshnav::eval
