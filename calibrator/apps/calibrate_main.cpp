/// meshnav_calibrate: offline anchor calibration (docs/calibration.md) on a dataset folder.
#include <spdlog/spdlog.h>

#include <Eigen/Cholesky>
#include <chrono>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "calibrator/anchor_calibrator.h"
#include "calibrator/calibration_io.h"
#include "calibrator/calibration_problem.h"
#include "calibrator/node/calibrator_config.h"
#include "calibrator/observation_builder.h"
#include "calibrator/range_model.h"
#include "common/cli_main.h"
#include "common/dataset.h"
#include "common/estimate_io.h"
#include "common/setup.h"

using namespace meshnav;
using namespace meshnav::calib;

namespace {

/// The command line of meshnav_calibrate.
struct CalibrateCli {
  std::string dataset, out, poses, config, loss, summary_csv, label = "run";
  std::vector<SensorId> anchors;
  bool no_ransac = false;
  double t_start_s = 0.0, t_end_s = 0.0, sigma_range_m = 0.0;
  uint64_t seed = CalibratorOptions{}.ransac_seed;
};

void declareOptions(Cli& cli, CalibrateCli& c) {
  cli.optional("dataset", c.dataset, "dataset folder: ranges.csv, setup.yaml, groundtruth.csv (truth.yaml optional)")
      ->type_name("DIR")->required();
  cli.idList("anchors", c.anchors, "ids of the anchors to calibrate (a known anchor is calibrated as if unknown)")
      ->required();
  cli.optional("out", c.out, "results YAML: id, p_AinG, p_AinG_cov, ref_ids, const_biases, ...")
      ->type_name("FILE.yaml")->required();
  cli.optional("poses", c.poses, "tag poses from this file (TUM or estimate.csv) instead of groundtruth.csv")
      ->type_name("CSV");
  cli.flag("no-ransac", c.no_ransac, "no RANSAC (robust loss only)");
  cli.optional("t-start", c.t_start_s, "use ranges with t >= S [s, dataset time] (default: all)")
      ->type_name("S")->check(cli::finite());
  cli.optional("t-end", c.t_end_s, "use ranges with t <= S [s, dataset time] (default: all)")
      ->type_name("S")->check(cli::finite());
  cli.optional("config", c.config, "calibrator options YAML (a 'calibrator:' map; keys in docs/calibration.md)")
      ->type_name("FILE");
  cli.optional("sigma-range", c.sigma_range_m,
               "range noise sigma_d [m] (default: config, else setup.yaml noise.sigma_range, else the built-in one)")
      ->type_name("M")->check(cli::positive());
  cli.optional("loss", c.loss, "robust loss of the refinement (default: the config's)")
      ->type_name("none|huber|cauchy")
      ->check(CLI::IsMember({"none", "huber", "cauchy"}));
  cli.option("seed", c.seed, "RANSAC seed")->type_name("N");
  cli.optional("summary-csv", c.summary_csv,
               "append one line per anchor: label,dataset,id,status,err_m,nees,crb_rmse_m,n_in,n_out,ms")
      ->type_name("FILE");
  cli.option("label", c.label, "label of the summary lines")->type_name("TEXT");
}

/// The calibrator options: --config, then the command line; σ_d from setup.yaml when neither sets it.
CalibratorOptions calibratorOptions(const Cli& cli, const CalibrateCli& c, const SystemSetup& setup) {
  CalibratorConfig config = CalibratorConfig::load(c.config);  // "" = the built-in defaults
  config.applySetup(setup);  // σ_d from setup.yaml unless the file sets it
  CalibratorOptions opt = config.calibrator;
  if (cli.given("sigma-range")) opt.sigma_range_m = c.sigma_range_m;
  if (!(opt.sigma_range_m > 0)) throw std::runtime_error("sigma_range must be > 0");
  if (!c.loss.empty()) opt.robust_loss = robustLossFromString(c.loss);
  if (c.no_ransac) opt.ransac = false;
  if (cli.given("seed")) opt.ransac_seed = c.seed;
  return opt;
}

bool looksLikeEstimateCsv(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line.find("pxx") != std::string::npos;
}

/// Error [m], NEES and CRB position RMSE [m] of one calibration against truth.yaml (NaN when unknown).
struct TruthFigures {
  double err = NAN, nees = NAN, crb = NAN;
};

TruthFigures truthFigures(const Truth& truth, SensorId id, const std::vector<CalibObservation>& obs,
                          const std::map<SensorId, ReferencePrior>& priors, const CalibratorOptions& opt,
                          const CalibrationResult& r) {
  TruthFigures f;
  if (!truth.anchor_positions.count(id)) return f;
  const Eigen::Vector3d p_true = truth.anchor_positions.at(id);
  const CalibrationProblem pb(id, obs, priors, opt);
  AnchorParams x = pb.priorParams(p_true);
  for (size_t s = 0; s < pb.slots().size(); ++s)
    for (const auto& b : truth.pair_biases)
      if (pairKey(b.a, b.b) == pairKey(pb.slots()[s].id, id)) {
        x.gamma_m[s] = b.gamma_m;
        if (pb.betaIndex(static_cast<int>(s)) >= 0) x.beta[s] = b.beta;
      }
  f.crb = crbPositionRmse(pb, x);
  if (r.ok()) {
    const Eigen::Vector3d e = r.p_AinG - p_true;
    f.err = e.norm();
    f.nees = e.dot(r.cov_p_m2.ldlt().solve(e));
  }
  return f;
}

void printHeader(bool with_truth) {
  std::printf("%-5s %-24s %6s %6s %6s %26s %18s", "id", "status", "ranges", "inl", "outl", "p_AinG [m]",
              "sigma xyz [m]");
  if (with_truth) std::printf(" %8s %8s %8s", "err [m]", "NEES", "CRB [m]");
  std::printf("\n");
}

void printRow(SensorId id, const CalibrationResult& r, const std::optional<TruthFigures>& f) {
  if (!r.ok()) {
    std::printf("%-5d %-24s %6d  refused: %s\n", id, toString(r.status), r.n_observations, r.reason.c_str());
    return;
  }
  std::printf("%-5d %-24s %6d %6d %6d [%7.3f %7.3f %7.3f] [%5.3f %5.3f %5.3f]", id, "ok", r.n_observations,
              r.n_inliers, r.n_outliers, r.p_AinG.x(), r.p_AinG.y(), r.p_AinG.z(), std::sqrt(r.cov_p_m2(0, 0)),
              std::sqrt(r.cov_p_m2(1, 1)), std::sqrt(r.cov_p_m2(2, 2)));
  if (f) std::printf(" %8.3f %8.2f %8.3f", f->err, f->nees, f->crb);
  std::printf("\n");
}

/// The summary CSV opened for appending (header written when it is new), or closed when not asked for.
std::ofstream openSummary(const std::string& path) {
  std::ofstream summary;
  if (path.empty()) return summary;
  const bool fresh = !std::filesystem::exists(path);
  summary.open(path, std::ios::app);
  if (!summary) throw std::runtime_error(path + ": cannot open for appending");
  if (fresh) summary << "label,dataset,id,status,err_m,nees,crb_rmse_m,n_in,n_out,ms\n";
  return summary;
}

/// The work of main: every anchor of --anchors calibrated and written to --out.
int calibrate(const Cli& cli, CalibrateCli& c) {
  const std::string& dir = c.dataset;
  Diagnostics diag;
  const SystemSetup setup = loadSetup(dir + "/setup.yaml");
  const CalibratorOptions opt = calibratorOptions(cli, c, setup);
  spdlog::debug("calibrator options:\n{}", opt.toString());

  const auto ranges = readRangesCsv(dir + "/ranges.csv", diag);
  ObservationBuilder builder(setup, opt);
  const std::string pose_path = c.poses.empty() ? dir + "/groundtruth.csv" : c.poses;
  if (looksLikeEstimateCsv(pose_path))
    builder.setPoses(readEstimateCsv(pose_path, diag));
  else
    builder.setPoses(readPosesAuto(pose_path, diag));
  std::optional<Truth> truth;
  if (std::filesystem::exists(dir + "/truth.yaml")) truth = loadTruth(dir + "/truth.yaml");

  std::optional<Timestamp> t0, t1;
  if (cli.given("t-start")) t0 = Timestamp::fromSec(c.t_start_s);
  if (cli.given("t-end")) t1 = Timestamp::fromSec(c.t_end_s);
  const Timestamp t_stamp = t1 ? *t1 : (ranges.empty() ? Timestamp{} : ranges.back().t);

  const AnchorCalibrator calibrator(opt);
  std::vector<CalibrationResult> results;
  std::ofstream summary = openSummary(c.summary_csv);
  printHeader(truth.has_value());
  for (SensorId id : c.anchors) {
    if (setup.isTag(id)) {
      spdlog::warn("{} is a tag in setup.yaml; skipped", id);
      continue;
    }
    const bool known = setup.isKnownAnchor(id);
    if (known) spdlog::info("anchor {} is known in setup.yaml; calibrating it as if unknown", id);
    const auto obs = builder.collect(id, ranges, diag, t0, t1);
    // A known anchor's a-priori pair biases were calibrated with its position: not used then.
    const auto priors = known ? std::map<SensorId, ReferencePrior>{} : builder.priors(id);
    const auto tic = std::chrono::steady_clock::now();
    CalibrationResult r = calibrator.calibrate(id, obs, priors, t_stamp);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tic).count();
    std::optional<TruthFigures> f;
    if (truth) f = truthFigures(*truth, id, obs, priors, opt, r);
    printRow(id, r, f);
    const TruthFigures shown = f.value_or(TruthFigures{});
    if (!c.summary_csv.empty())  // a failed write is found by the checked flush below
      summary << c.label << "," << dir << "," << id << "," << toString(r.status) << "," << shown.err << ","
              << shown.nees << "," << shown.crb << "," << r.n_inliers << "," << r.n_outliers << "," << ms << "\n";
    results.push_back(std::move(r));
  }
  if (!c.summary_csv.empty()) checkedFlush(summary, c.summary_csv);
  writeCalibrationYaml(results, c.out);
  if (diag.total() > 0) spdlog::info("input diagnostics: {}", diag.summary());
  spdlog::info("wrote {}", c.out);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return cliMain<CalibrateCli>(argc, argv, "meshnav_calibrate",
                               "Offline anchor calibration (optimal double + Levenberg-Marquardt + RANSAC).",
                               declareOptions, calibrate);
}
