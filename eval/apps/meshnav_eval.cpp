/// @file meshnav_eval.cpp
/// @brief Evaluates a run against ground truth (pose RMSE/ARMSE/ANEES, anchor errors), writes
/// metrics.yaml, errors.csv and plots; or, with --batch, the paper-style table over many runs.

#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>

#include "common/cli.h"
#include "eval/plotting.h"
#include "eval/report.h"
#include "eval/run_evaluation.h"

namespace fs = std::filesystem;
using namespace meshnav;
using namespace meshnav::eval;

namespace {

const char* kUsage = R"(meshnav_eval — metrics of a run against ground truth, and plots.

Single run:
  meshnav_eval --dataset DIR --run DIR [--out DIR] [--no-plots] [--json FILE] [--align none|se3|yaw]
Multilateration baseline only (no run):
  meshnav_eval --dataset DIR [--align none|se3|yaw] [--out DIR]
Many runs (paper-style table):
  meshnav_eval --batch ROOT [--table-md FILE] [--dataset-subdir NAME] [--run-subdir NAME] [--plots]

Options:
  --dataset DIR         dataset folder (groundtruth.csv, truth.yaml, setup.yaml, flight_state.csv)
  --run DIR             run folder (estimate.csv, anchors.csv, optional calibration.yaml)
  --out DIR             where metrics.yaml, errors.csv, anchors_eval.csv and PNGs go (default: --run)
  --no-plots            do not call eval/plots/plot_run.py
  --json FILE           also write the metrics as JSON
  --skip S              ignore the first S seconds after the first estimate [s] (default 0)
  --only-flying         evaluate only while not landed (flight_state.csv); default: all samples
  --max-gt-gap S        largest ground-truth gap that is interpolated [s] (default 0.2)
  --align MODE          none | se3 | yaw: align the estimate (and the baseline, each with its own
                        fit) to the ground truth before the errors are taken: se3 = rotation +
                        translation (Umeyama, no scale), yaw = rotation about z + translation.
                        Default: se3 when truth.yaml says align_required (truth in another frame,
                        e.g. imported real recordings), else none. The table states the mode used.
  --no-baseline         do not run the multilateration baseline on the dataset's ranges.csv
  --baseline-window S   epoch length of the multilateration baseline [s] (default 0.03: shorter than
                        the 51 ms between two RTLS messages of ISAS-Walk1, so one message = one epoch)
  --calibration FILE    calibration result YAML giving the initial anchor beliefs
                        (default: RUN/calibration.yaml if present, else first anchors.csv row)
  --batch ROOT          evaluate every ROOT/<name>/ holding <dataset-subdir>/ and <run-subdir>/
  --dataset-subdir NAME (batch) dataset folder name inside each run folder (default dataset)
  --run-subdir NAME     (batch) run folder name inside each run folder (default run)
  --table-md FILE       (batch) write the table as Markdown to FILE
  --plots               (batch) also write plots of every run (default: no plots in batch mode)
  --help                this text

Errors are truth minus estimate. RMSE = sqrt(mean |e|^2); ARMSE = mean |e| (the toolbox's
"ARMSE"); NEES = e^T P^-1 e per sample (chi2, 3 dof), ANEES its mean with the 95 % interval.
Exit status: 0 ok, 1 nothing could be evaluated, 2 usage error, 3 evaluated, but rows of the
ground truth or the estimate were skipped for a time stamp that is not a number or does not fit
(the figures leave those rows out: do not trust them before the file is fixed).
)";

EvalOptions optionsFrom(const Cli& cli) {
  EvalOptions o;
  o.skip_first_s = cli.getDouble("skip", 0.0);
  o.only_flying = cli.has("only-flying");
  o.max_gt_gap_s = cli.getDouble("max-gt-gap", 0.2);
  o.baseline = !cli.has("no-baseline");
  o.baseline_window_s = cli.getDouble("baseline-window", 0.03);
  if (cli.has("align")) {
    o.align = parseAlignmentMode(cli.get("align"));
    if (!o.align) throw std::invalid_argument("--align '" + cli.get("align") + "': expected none, se3 or yaw");
  }
  if (!(o.baseline_window_s > 0.0)) throw std::invalid_argument("--baseline-window must be > 0 [s]");
  return o;
}

void writeOutputs(const RunEvaluation& ev, const fs::path& out, bool plots, const std::string& dataset) {
  fs::create_directories(out);
  writeMetricsYaml(ev, (out / "metrics.yaml").string());
  writeErrorsCsv(ev, (out / "errors.csv").string());
  writeAnchorsEvalCsv(ev, (out / "anchors_eval.csv").string());
  spdlog::info("wrote {}, errors.csv, anchors_eval.csv", (out / "metrics.yaml").string());
  if (!plots) return;
  std::vector<std::string> args = {"--out", out.string(), "--errors", (out / "errors.csv").string(),
                                   "--anchors", (out / "anchors_eval.csv").string()};
  const fs::path gt = fs::path(dataset) / "groundtruth.csv";
  const fs::path est = fs::path(ev.run_dir) / "estimate.csv";
  if (fs::exists(gt)) args.insert(args.end(), {"--groundtruth", gt.string()});
  if (fs::exists(est)) args.insert(args.end(), {"--estimate", est.string()});
  if (runPlotScript("plot_run.py", args)) spdlog::info("plots written to {}", out.string());
}

/// No --run: the multilateration baseline of the dataset alone (metrics.yaml only with --out).
int runBaselineOnly(const std::string& dataset, const EvalOptions& options, const Cli& cli) {
  if (!fs::is_directory(dataset)) {
    spdlog::error("{} is not a directory", dataset);
    return 1;
  }
  const RunEvaluation ev = evaluateRun(dataset, "", options);
  std::cout << formatRunReport(ev) << std::flush;
  if (cli.has("out")) {
    fs::create_directories(cli.get("out"));
    writeMetricsYaml(ev, (fs::path(cli.get("out")) / "metrics.yaml").string());
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

int runSingle(const Cli& cli) {
  if (!cli.has("dataset")) {
    std::cerr << "meshnav_eval: --dataset is required (or --batch ROOT)\n\n" << cli.usage();
    return 2;
  }
  EvalOptions options;
  try {
    options = optionsFrom(cli);
  } catch (const std::invalid_argument& ex) {
    std::cerr << "meshnav_eval: " << ex.what() << "\n\n" << cli.usage();
    return 2;
  }
  const std::string dataset = cli.get("dataset"), run = cli.get("run");
  if (run.empty()) return runBaselineOnly(dataset, options, cli);
  for (const auto& d : {dataset, run})
    if (!fs::is_directory(d)) {
      spdlog::error("{} is not a directory", d);
      return 1;
    }
  RunEvaluation ev = evaluateRun(dataset, run, options, cli.get("calibration"));
  std::cout << formatRunReport(ev) << std::flush;
  const fs::path out = cli.has("out") ? fs::path(cli.get("out")) : fs::path(run);
  try {
    writeOutputs(ev, out, !cli.has("no-plots"), dataset);
    if (cli.has("json")) writeMetricsJson(ev, cli.get("json"));
  } catch (const std::exception& ex) {
    spdlog::error("{}", ex.what());
    return 1;
  }
  if (!(ev.trajectory.n_selected > 0 || ev.anchors)) return 1;
  return badTimeRows(ev) ? 3 : 0;
}

int runBatch(const Cli& cli) {
  const fs::path root = cli.get("batch");
  if (!fs::is_directory(root)) {
    spdlog::error("--batch {}: not a directory", root.string());
    return 1;
  }
  const std::string ds_name = cli.get("dataset-subdir", "dataset");
  const std::string run_name = cli.get("run-subdir", "run");
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
  EvalOptions opt;
  try {
    opt = optionsFrom(cli);
  } catch (const std::invalid_argument& ex) {
    std::cerr << "meshnav_eval: " << ex.what() << "\n";
    return 2;
  }
  for (size_t i = 0; i < dirs.size(); ++i) {
    const auto& d = dirs[i];
    spdlog::info("[{}/{}] evaluating {}", i + 1, dirs.size(), d.filename().string());
    BatchEntry e{d.filename().string(),
                 evaluateRun((d / ds_name).string(), (d / run_name).string(), opt)};
    try {
      writeOutputs(e.ev, d / run_name, cli.has("plots"), (d / ds_name).string());
    } catch (const std::exception& ex) {
      spdlog::warn("{}: {}", d.string(), ex.what());
    }
    entries.push_back(std::move(e));
  }
  const TextTable table = makeBatchTable(entries);
  std::cout << "\nmeshnav evaluation of " << entries.size() << " runs under " << root.string() << "\n"
            << "(★ = initial anchor estimate from the calibration, no mark = final filter estimate; "
               "errors in m, orientation in deg)\n\n"
            << table.plain() << std::flush;
  if (cli.has("table-md")) {
    std::ofstream f(cli.get("table-md"));
    if (!f) {
      spdlog::error("cannot write {}", cli.get("table-md"));
      return 1;
    }
    f << "<!-- generated by meshnav_eval --batch " << root.string() << " -->\n"
      << "Pose RMSE (position [m], orientation [deg]), ANEES (3 dof each; consistent ≈ 3) and anchor "
         "position errors [m] of the initial (★) and final estimates.\n\n"
      << table.markdown();
    spdlog::info("wrote {}", cli.get("table-md"));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  setupLogging("meshnav_eval");
  Cli cli("meshnav_eval", kUsage);
  for (const char* o : {"dataset", "run", "out", "json", "skip", "max-gt-gap", "calibration", "batch",
                        "dataset-subdir", "run-subdir", "table-md", "align", "baseline-window"})
    cli.option(o, true);
  for (const char* f : {"no-plots", "only-flying", "plots", "no-baseline"}) cli.option(f, false);
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  try {
    return cli.has("batch") ? runBatch(cli) : runSingle(cli);
  } catch (const std::exception& ex) {
    spdlog::error("{}", ex.what());
    return 1;
  }
}
