/// @file meshnav_eval.cpp
/// @brief Evaluates a run against ground truth (pose RMSE/ARMSE/ANEES, anchor errors), writes
/// metrics.yaml, errors.csv and plots; or, with --batch, the paper-style table over many runs.

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <utility>

#include "common/atomic_file.h"
#include "common/cli_main.h"
#include "common/fleet_file.h"
#include "eval/plotting.h"
#include "eval/report.h"
#include "eval/run_evaluation.h"

namespace fs = std::filesystem;
using namespace meshnav;
using namespace meshnav::eval;

namespace {

constexpr char kDescription[] =
    "Metrics of a run against ground truth (pose RMSE, ARMSE, ANEES, anchor errors) and plots; the "
    "multilateration baseline of a dataset alone (no --run); or, with --batch, the paper-style table over many "
    "runs. Exit status 0: evaluated; 1: nothing to evaluate (no estimate could be scored against the ground truth, "
    "or a file could not be read or written); 2: bad command line; 3: rows with unusable time stamps were left "
    "out.";

/// "T0:T1" [s] with finite T0 < T1; nullopt otherwise.
std::optional<std::pair<double, double>> parseWindow(const std::string& w) {
  const size_t colon = w.find(':');
  if (colon == std::string::npos) return std::nullopt;
  try {
    size_t n0 = 0, n1 = 0;
    const std::string a = w.substr(0, colon), b = w.substr(colon + 1);
    const double t0 = std::stod(a, &n0), t1 = std::stod(b, &n1);
    if (n0 != a.size() || n1 != b.size() || !std::isfinite(t0) || !std::isfinite(t1) || !(t0 < t1))
      return std::nullopt;
    (void)Timestamp::fromSec(t0), (void)Timestamp::fromSec(t1);  // throws beyond the int64 µs range
    return std::pair{t0, t1};
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

/// The command line of meshnav_eval (EvalOptions holds the defaults of the metric options).
struct EvalCli {
  EvalOptions eval;
  bool no_baseline = false, no_truth_check = false;
  std::string align;
  std::string dataset, run, out, json, calibration, batch, table_md, fleet;
  std::string dataset_subdir = "dataset", run_subdir = "run";
  std::vector<std::string> exclude;
  bool no_plots = false, plots = false;
};

void declareOptions(Cli& cli, EvalCli& c) {
  const std::string batch = "Many runs (--batch)";
  cli.optional("dataset", c.dataset, "dataset folder (groundtruth.csv, truth.yaml, setup.yaml, flight_state.csv); "
                                     "without --run: the multilateration baseline only")->type_name("DIR");
  cli.optional("run", c.run, "run folder (estimate.csv, anchors.csv, optional calibration.yaml)")->type_name("DIR");
  cli.optional("out", c.out, "where metrics.yaml, errors.csv, anchors_eval.csv and PNGs go (default: --run)")
      ->type_name("DIR");
  cli.flag("no-plots", c.no_plots, "do not call eval/plots/plot_run.py");
  cli.optional("json", c.json, "also write the metrics as JSON")->type_name("FILE");
  cli.option("skip", c.eval.skip_first_s, "ignore the first S seconds after the first estimate [s]")
      ->type_name("S")->check(cli::nonNegative());
  cli.flag("only-flying", c.eval.only_flying, "evaluate only while not landed (flight_state.csv); default: all samples");
  cli.flag("no-truth-check", c.no_truth_check,
           "keep the ground truth where it contradicts imu.csv's gyro (by default those windows are left out and "
           "listed: a motion-capture dropout; eval/truth_consistency.h)");
  cli.optional("exclude", c.exclude,
               "leave out the ground truth of dataset times T0 to T1 [s] (the files' stamps), given as T0:T1, so that "
               "the estimates there enter neither the alignment nor the figures (a sensor outage scored apart); "
               "repeatable")
      ->type_name("WINDOW")
      ->check(CLI::Validator(
          [](std::string& w) -> std::string {
            return parseWindow(w) ? std::string() : "'" + w + "' is not a window T0:T1 [s] with T0 < T1";
          },
          "T0 < T1"));
  cli.option("max-gt-gap", c.eval.max_gt_gap_s, "largest ground-truth gap that is interpolated [s]")
      ->type_name("S")->check(cli::positive());
  cli.optional("align", c.align,
               "align the estimate (and the baseline, each with its own fit) to the ground truth before the errors "
               "are taken: se3 = rotation + translation (Umeyama, no scale), yaw = rotation about z + translation. "
               "Default: se3 when truth.yaml says align_required (truth in another frame, e.g. imported real "
               "recordings), else none. The table states the mode used")
      ->type_name("none|se3|yaw")
      ->check(cli::oneOf([](const std::string& m) { return parseAlignmentMode(m).has_value(); }, "none|se3|yaw"));
  cli.flag("no-baseline", c.no_baseline, "do not run the multilateration baseline on the dataset's ranges.csv");
  cli.option("baseline-window", c.eval.baseline_window_s,
             "epoch length of the multilateration baseline [s] (shorter than the 51 ms between two RTLS messages "
             "of ISAS-Walk1, so one message = one epoch)")
      ->type_name("S")->check(cli::positive());
  cli.optional("calibration", c.calibration,
               "calibration result YAML giving the initial anchor beliefs (default: RUN/calibration.yaml if "
               "present, else first anchors.csv row)")
      ->type_name("FILE");
  cli.optional("batch", c.batch, "evaluate every ROOT/<name>/ holding <dataset-subdir>/ and <run-subdir>/")
      ->type_name("ROOT")->group(batch);
  cli.option("dataset-subdir", c.dataset_subdir, "dataset folder name inside each run folder")
      ->type_name("NAME")->group(batch);
  cli.option("run-subdir", c.run_subdir, "run folder name inside each run folder")->type_name("NAME")->group(batch);
  cli.optional("table-md", c.table_md, "write the table as Markdown to FILE")->type_name("FILE")->group(batch);
  cli.flag("plots", c.plots, "also write plots of every run (default: no plots in batch mode)")->group(batch);
  cli.optional("fleet", c.fleet,
               "a fleet run (meshnav run --fleet FILE --out RUN; docs/fleet.md): with --run RUN, each vehicle's "
               "RUN/<name> against its dataset of FILE, one row per vehicle and the fleet's mean; the initial "
               "anchors from RUN/calibration.yaml, the fleet's one calibration")
      ->type_name("FILE")->group("A fleet (--fleet)");
  cli.app().footer(
      "Errors are truth minus estimate. RMSE = sqrt(mean |e|^2); ARMSE = mean |e| (the toolbox's \"ARMSE\"); NEES = "
      "e^T P^-1 e per sample (chi2, 3 dof), ANEES its mean with the 95 % interval.\nExit status: 0 ok, 1 nothing "
      "could be evaluated, 2 usage error.");
}

/// The metric options after the parse.
EvalOptions optionsFrom(const EvalCli& c) {
  EvalOptions o = c.eval;
  o.baseline = !c.no_baseline;
  o.check_truth_with_gyro = !c.no_truth_check;
  if (!c.align.empty()) o.align = parseAlignmentMode(c.align);
  for (const std::string& w : c.exclude) o.exclude_windows_s.push_back(*parseWindow(w));
  return o;
}

void writeOutputs(const RunEvaluation& ev, const fs::path& out, bool plots, const std::string& dataset) {
  fs::create_directories(out);
  writeMetricsYaml(ev, (out / "metrics.yaml").string());
  writeErrorsCsv(ev, (out / "errors.csv").string());
  if (ev.smoothed) writeSmoothedErrorsCsv(ev, (out / "errors_smoothed.csv").string());
  writeAnchorsEvalCsv(ev, (out / "anchors_eval.csv").string());
  spdlog::info("wrote {}, errors.csv, anchors_eval.csv", (out / "metrics.yaml").string());
  if (!plots) return;
  std::vector<std::string> args = {"--out", out.string(), "--errors", (out / "errors.csv").string(),
                                   "--anchors", (out / "anchors_eval.csv").string()};
  const fs::path gt = fs::path(dataset) / "groundtruth.csv";
  const fs::path est = fs::path(ev.run_dir) / "estimate.csv";
  if (fs::exists(gt)) args.insert(args.end(), {"--groundtruth", gt.string()});
  if (fs::exists(est)) args.insert(args.end(), {"--estimate", est.string()});
  if (ev.smoothed)
    args.insert(args.end(), {"--smoothed", (fs::path(ev.run_dir) / "estimate_smoothed.csv").string(),
                             "--smoothed-errors", (out / "errors_smoothed.csv").string()});
  const fs::path track = fs::path(ev.run_dir) / "anchors.csv";
  if (fs::exists(track)) args.insert(args.end(), {"--anchor-track", track.string()});
  // Truth in another frame: the plot draws it mapped into the estimate's frame with the fitted (R, t).
  if (ev.alignment != AlignmentMode::None && ev.alignment_transform) {
    const RigidTransform& a = *ev.alignment_transform;
    std::string rt;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) rt += fmt::format("{:.17g},", a.R_EtoT(r, c));
    rt += fmt::format("{:.17g},{:.17g},{:.17g}", a.t_EinT_m.x(), a.t_EinT_m.y(), a.t_EinT_m.z());
    args.insert(args.end(), {"--alignment", rt, "--alignment-mode", toString(ev.alignment)});
  }
  // Range residuals along the estimate: the dataset's ranges, tag lever arms and known anchors.
  for (const auto& [flag, file] : {std::pair{"--ranges", "ranges.csv"}, std::pair{"--setup", "setup.yaml"}})
    if (const fs::path f = fs::path(dataset) / file; fs::exists(f)) args.insert(args.end(), {flag, f.string()});
  if (runPlotScript("plot_run.py", args)) spdlog::info("plots written to {}", out.string());
}

/// No --run: the multilateration baseline of the dataset alone (metrics.yaml only with --out).
int runBaselineOnly(const std::string& dataset, const EvalOptions& options, const EvalCli& cli) {
  if (!fs::is_directory(dataset)) {
    spdlog::error("{} is not a directory", dataset);
    return 1;
  }
  const RunEvaluation ev = evaluateRun(dataset, "", options);
  std::cout << formatRunReport(ev) << std::flush;
  if (!cli.out.empty()) {
    fs::create_directories(cli.out);
    writeMetricsYaml(ev, (fs::path(cli.out) / "metrics.yaml").string());
  }
  return ev.baseline && ev.baseline->trajectory.n_selected > 0 ? 0 : 1;
}

/// Rows skipped for an unusable time stamp ("<file>:bad_time"): reported, and a failed exit.
bool badTimeRows(const RunEvaluation& ev) {
  const int64_t n = skippedTimeRows(ev);
  if (n > 0)
    spdlog::error("{} input row(s) skipped for a time stamp that is not a number or does not fit (see the "
                  "messages above): the figures leave them out; exit status 3",
                  n);
  return n > 0;
}

int runSingle(const EvalCli& cli) {
  if (cli.dataset.empty()) {
    std::cerr << "meshnav_eval: --dataset is required (or --batch ROOT, or --fleet FILE); see --help\n";
    return 2;
  }
  const EvalOptions options = optionsFrom(cli);
  if (cli.run.empty()) return runBaselineOnly(cli.dataset, options, cli);
  for (const auto& d : {cli.dataset, cli.run})
    if (!fs::is_directory(d)) {
      spdlog::error("{} is not a directory", d);
      return 1;
    }
  RunEvaluation ev = evaluateRun(cli.dataset, cli.run, options, cli.calibration);
  std::cout << formatRunReport(ev) << std::flush;
  const fs::path out = cli.out.empty() ? fs::path(cli.run) : fs::path(cli.out);
  try {
    writeOutputs(ev, out, !cli.no_plots, cli.dataset);
    if (!cli.json.empty()) writeMetricsJson(ev, cli.json);
  } catch (const std::exception& ex) {
    spdlog::error("{}", ex.what());
    return 1;
  }
  if (!(ev.trajectory.n_selected > 0 || ev.anchors)) return 1;
  // Windows that left no pose to score make the run's figures missing, not healthy.
  if (!ev.options.exclude_windows_s.empty() && ev.trajectory.n_selected == 0) {
    spdlog::error("--exclude left no estimate to score");
    return 1;
  }
  // Ground truth to score against and no pose scored: the run's result is missing, whatever the
  // anchors say (issue 36: this used to exit 0 with "pose metrics: not available").
  if (ev.has_ground_truth && ev.trajectory.n_selected == 0) {
    spdlog::error("no estimate of {} could be scored against the ground truth of {}: pose metrics not available{}",
                  cli.run, cli.dataset, ev.notes.empty() ? std::string() : " (" + ev.notes.back() + ")");
    return 1;
  }
  return badTimeRows(ev) ? 3 : 0;
}

/// Prints the batch table of `entries` (one row per run and their mean) and writes it as Markdown
/// when asked; `what` names them in the heading.
void printBatchTables(const std::vector<BatchEntry>& entries, const std::string& what, const EvalCli& cli) {
  const TextTable table = makeBatchTable(entries);
  std::cout << "\nmeshnav evaluation of " << what << "\n"
            << "(★ = initial anchor estimate from the calibration, no mark = final filter estimate; "
               "errors in m, orientation in deg)\n\n"
            << table.plain() << std::flush;
  const TextTable anchors = makeBatchAnchorSummary(entries);
  const bool have_anchors = !anchors.empty();
  if (have_anchors)
    std::cout << "\nEstimated anchors over all runs (NEES: 3 dof, 99.7 % bound 13.93)\n\n" << anchors.plain() << std::flush;
  if (!cli.table_md.empty()) {
    writeFileAtomically(cli.table_md, [&](std::ostream& f) {
      f << "<!-- generated by meshnav_eval of " << what << " -->\n"
        << "Pose RMSE (position [m], orientation [deg]), ANEES (3 dof each; consistent ≈ 3) and anchor "
           "position errors [m] of the initial (★) and final estimates.\n\n"
        << table.markdown();
      if (have_anchors)
        f << "\nEstimated anchors over all runs (NEES: 3 dof, 99.7 % bound 13.93):\n\n" << anchors.markdown();
    });
    spdlog::info("wrote {}", cli.table_md);
  }
}

/// `--fleet FILE --run RUN`: every vehicle of the fleet file scored in RUN/<name>. Exit 1 when a
/// vehicle's run folder is missing or none of its poses could be scored (a fleet run with one
/// vehicle lost is not healthy).
int runFleet(const EvalCli& cli) {
  if (cli.run.empty() || !cli.dataset.empty() || !cli.batch.empty()) {
    std::cerr << "meshnav_eval: --fleet FILE needs --run RUN (the fleet run's folder) and no --dataset or --batch\n";
    return 2;
  }
  std::vector<FleetEntry> vehicles;
  try {
    vehicles = loadFleetFile(cli.fleet);
  } catch (const std::exception& ex) {
    spdlog::error("{}", ex.what());
    return 1;
  }
  const EvalOptions opt = optionsFrom(cli);
  const fs::path run_root = cli.run;
  const std::string calibration =
      cli.calibration.empty() && fs::exists(run_root / "calibration.yaml") ? (run_root / "calibration.yaml").string()
                                                                            : cli.calibration;
  std::vector<BatchEntry> entries;
  int rc = 0;
  for (size_t i = 0; i < vehicles.size(); ++i) {
    const FleetEntry& v = vehicles[i];
    const fs::path run = run_root / v.name;
    if (!fs::is_directory(run) || !fs::is_directory(v.dataset)) {
      spdlog::error("{}: vehicle {}: {} is not a directory", cli.fleet, v.name,
                    fs::is_directory(run) ? v.dataset : run.string());
      rc = 1;
      continue;
    }
    spdlog::info("[{}/{}] evaluating vehicle {}", i + 1, vehicles.size(), v.name);
    BatchEntry e{v.name, evaluateRun(v.dataset, run.string(), opt, calibration)};
    try {
      writeOutputs(e.ev, run, cli.plots, v.dataset);
    } catch (const std::exception& ex) {
      spdlog::warn("{}: {}", run.string(), ex.what());
    }
    if (e.ev.has_ground_truth && e.ev.trajectory.n_selected == 0) {
      spdlog::error("vehicle {}: no estimate of {} could be scored against the ground truth of {}", v.name,
                    run.string(), v.dataset);
      rc = 1;
    }
    if (badTimeRows(e.ev) && rc == 0) rc = 3;
    entries.push_back(std::move(e));
  }
  if (entries.empty()) return 1;
  printBatchTables(entries, std::to_string(entries.size()) + " vehicles of the fleet " + cli.fleet + " in " +
                                run_root.string(), cli);
  return rc;
}

int runBatch(const EvalCli& cli) {
  const fs::path root = cli.batch;
  if (!fs::is_directory(root)) {
    spdlog::error("--batch {}: not a directory", root.string());
    return 1;
  }
  const std::string& ds_name = cli.dataset_subdir;
  const std::string& run_name = cli.run_subdir;
  std::vector<fs::path> dirs;
  for (const auto& e : fs::directory_iterator(root))
    if (e.is_directory() && fs::is_directory(e.path() / ds_name) && fs::is_directory(e.path() / run_name))
      dirs.push_back(e.path());
  std::sort(dirs.begin(), dirs.end());
  if (dirs.empty()) {
    spdlog::error("--batch {}: no sub-folder holds both {}/ and {}/", root.string(), ds_name, run_name);
    return 1;
  }
  std::vector<BatchEntry> entries;
  const EvalOptions opt = optionsFrom(cli);
  for (size_t i = 0; i < dirs.size(); ++i) {
    const auto& d = dirs[i];
    spdlog::info("[{}/{}] evaluating {}", i + 1, dirs.size(), d.filename().string());
    BatchEntry e{d.filename().string(),
                 evaluateRun((d / ds_name).string(), (d / run_name).string(), opt)};
    try {
      writeOutputs(e.ev, d / run_name, cli.plots, (d / ds_name).string());
    } catch (const std::exception& ex) {
      spdlog::warn("{}: {}", d.string(), ex.what());
    }
    entries.push_back(std::move(e));
  }
  printBatchTables(entries, std::to_string(entries.size()) + " runs under " + root.string(), cli);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return cliMain<EvalCli>(argc, argv, "meshnav_eval", kDescription, declareOptions, [](const Cli&, EvalCli& c) {
    if (!c.fleet.empty()) return runFleet(c);
    return c.batch.empty() ? runSingle(c) : runBatch(c);
  });
}
