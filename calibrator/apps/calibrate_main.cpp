/// meshnav_calibrate: offline anchor calibration (DESIGN §5/§6/§8) on a dataset folder.
#include <spdlog/spdlog.h>

#include <Eigen/Cholesky>
#include <chrono>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "calibrator/anchor_calibrator.h"
#include "calibrator/calibration_io.h"
#include "calibrator/calibration_problem.h"
#include "calibrator/node/calibrator_config.h"
#include "calibrator/observation_builder.h"
#include "calibrator/range_model.h"
#include "common/cli.h"
#include "common/dataset.h"
#include "common/estimate_io.h"
#include "common/setup.h"

using namespace meshnav;
using namespace meshnav::calib;

namespace {

const char* kUsage = R"(Offline anchor calibration (optimal double + Levenberg-Marquardt + RANSAC).

Usage: meshnav_calibrate --dataset DIR --anchors ID,ID,... --out FILE.yaml [options]

  --dataset DIR        dataset folder: ranges.csv, setup.yaml, groundtruth.csv (truth.yaml optional)
  --anchors LIST       comma separated ids of the anchors to calibrate (a known anchor is
                       calibrated as if unknown)
  --out FILE.yaml      results (DESIGN §6): id, p_AinG, p_AinG_cov, ref_ids, const_biases, ...
  --poses CSV          tag poses from this file (TUM or estimate.csv) instead of groundtruth.csv
  --no-ransac          no RANSAC (robust loss only)
  --t-start S          use ranges with t >= S [s, dataset time] (default: all)
  --t-end S            use ranges with t <= S [s, dataset time] (default: all)
  --config FILE        calibrator options YAML (a 'calibrator:' map; keys in docs/calibration.md)
  --sigma-range M      range noise sigma_d [m] (default: config, else setup.yaml noise.sigma_range, else 0.1)
  --loss NAME          robust loss of the refinement: none | huber | cauchy (default cauchy)
  --seed N             RANSAC seed (default 1)
  --summary-csv FILE   append one line per anchor: label,dataset,id,status,err_m,nees,crb_rmse_m,n_in,n_out,ms
  --label TEXT         label of the summary lines (default "run")
  --help               this text
)";

/// "106,107" → ids; a token that is not a whole number in 1..INT32_MAX is an error naming it
/// (4294967297 used to wrap to anchor 1).
std::vector<SensorId> parseIds(const std::string& s) {
  std::vector<SensorId> ids;
  std::stringstream ss(s);
  std::string tok;
  while (std::getline(ss, tok, ',')) {
    if (tok.empty()) continue;
    errno = 0;
    char* end = nullptr;
    const long long v = std::strtoll(tok.c_str(), &end, 10);
    if (end == tok.c_str() || *end != '\0' || errno == ERANGE || v < 1 || v > INT32_MAX)
      throw std::invalid_argument("--anchors: '" + tok + "' is not an anchor id (an integer in 1.." +
                                  std::to_string(INT32_MAX) + ")");
    ids.push_back(static_cast<SensorId>(v));
  }
  return ids;
}

bool looksLikeEstimateCsv(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line.find("pxx") != std::string::npos;
}

}  // namespace

int main(int argc, char** argv) {
  setupLogging("meshnav_calibrate");
  Cli cli("meshnav_calibrate", kUsage);
  for (const char* o : {"dataset", "anchors", "out", "poses", "t-start", "t-end", "config", "sigma-range", "loss", "seed",
                        "summary-csv", "label"})
    cli.option(o);
  cli.option("no-ransac", false);
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  if (!cli.has("dataset") || !cli.has("anchors") || !cli.has("out")) {
    std::fprintf(stderr, "meshnav_calibrate: --dataset, --anchors and --out are required\n\n%s", kUsage);
    return 2;
  }
  const std::string dir = cli.get("dataset");
  try {
    const std::vector<SensorId> anchor_ids = parseIds(cli.get("anchors"));
    Diagnostics diag;
    CalibratorOptions opt = cli.has("config") ? CalibratorConfig::load(cli.get("config")).calibrator : CalibratorOptions{};
    const SystemSetup setup = loadSetup(dir + "/setup.yaml");
    if (cli.has("sigma-range")) {
      opt.sigma_range_m = cli.getDouble("sigma-range", opt.sigma_range_m);
    } else if (!cli.has("config") && setup.noise.sigma_range_m) {
      opt.sigma_range_m = *setup.noise.sigma_range_m;
    }
    if (!(opt.sigma_range_m > 0)) throw std::runtime_error("--sigma-range must be > 0");
    if (cli.has("loss")) opt.robust_loss = robustLossFromString(cli.get("loss"));
    if (cli.has("no-ransac")) opt.ransac = false;
    if (cli.has("seed")) opt.ransac_seed = static_cast<uint64_t>(cli.getInt("seed", 1));
    spdlog::debug("calibrator options:\n{}", opt.toString());

    const auto ranges = readRangesCsv(dir + "/ranges.csv", diag);
    ObservationBuilder builder(setup, opt);
    const std::string pose_path = cli.has("poses") ? cli.get("poses") : dir + "/groundtruth.csv";
    if (looksLikeEstimateCsv(pose_path)) {
      builder.setPoses(readEstimateCsv(pose_path, diag));
    } else {
      builder.setPoses(readPosesAuto(pose_path, diag));
    }
    std::optional<Truth> truth;
    if (std::filesystem::exists(dir + "/truth.yaml")) truth = loadTruth(dir + "/truth.yaml");

    std::optional<Timestamp> t0, t1;
    if (cli.has("t-start")) t0 = Timestamp::fromSec(cli.getDouble("t-start", 0.0));
    if (cli.has("t-end")) t1 = Timestamp::fromSec(cli.getDouble("t-end", 0.0));
    Timestamp t_stamp = t1 ? *t1 : (ranges.empty() ? Timestamp{} : ranges.back().t);

    const AnchorCalibrator calibrator(opt);
    std::vector<CalibrationResult> results;
    std::ofstream summary;
    if (cli.has("summary-csv")) {
      const bool fresh = !std::filesystem::exists(cli.get("summary-csv"));
      summary.open(cli.get("summary-csv"), std::ios::app);
      if (!summary) throw std::runtime_error(cli.get("summary-csv") + ": cannot open for appending");
      if (fresh) summary << "label,dataset,id,status,err_m,nees,crb_rmse_m,n_in,n_out,ms\n";
    }

    std::printf("%-5s %-24s %6s %6s %6s %26s %18s", "id", "status", "ranges", "inl", "outl", "p_AinG [m]",
                "sigma xyz [m]");
    if (truth) std::printf(" %8s %8s %8s", "err [m]", "NEES", "CRB [m]");
    std::printf("\n");
    for (SensorId id : anchor_ids) {
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
      double err = NAN, nees = NAN, crb = NAN;
      if (truth && truth->anchor_positions.count(id)) {
        const Eigen::Vector3d p_true = truth->anchor_positions.at(id);
        const CalibrationProblem pb(id, obs, priors, opt);
        AnchorParams x = pb.priorParams(p_true);
        for (size_t s = 0; s < pb.slots().size(); ++s)
          for (const auto& b : truth->pair_biases)
            if (pairKey(b.a, b.b) == pairKey(pb.slots()[s].id, id)) {
              x.gamma_m[s] = b.gamma_m;
              if (pb.betaIndex(static_cast<int>(s)) >= 0) x.beta[s] = b.beta;
            }
        crb = crbPositionRmse(pb, x);
        if (r.ok()) {
          const Eigen::Vector3d e = r.p_AinG - p_true;
          err = e.norm();
          nees = e.dot(r.cov_p_m2.ldlt().solve(e));
        }
      }
      if (r.ok()) {
        std::printf("%-5d %-24s %6d %6d %6d [%7.3f %7.3f %7.3f] [%5.3f %5.3f %5.3f]", id, "ok", r.n_observations,
                    r.n_inliers, r.n_outliers, r.p_AinG.x(), r.p_AinG.y(), r.p_AinG.z(), std::sqrt(r.cov_p_m2(0, 0)),
                    std::sqrt(r.cov_p_m2(1, 1)), std::sqrt(r.cov_p_m2(2, 2)));
        if (truth) std::printf(" %8.3f %8.2f %8.3f", err, nees, crb);
        std::printf("\n");
      } else {
        std::printf("%-5d %-24s %6d  refused: %s\n", id, toString(r.status), r.n_observations, r.reason.c_str());
      }
      if (summary)
        summary << cli.get("label", "run") << "," << dir << "," << id << "," << toString(r.status) << "," << err << ","
                << nees << "," << crb << "," << r.n_inliers << "," << r.n_outliers << "," << ms << "\n";
      results.push_back(std::move(r));
    }
    writeCalibrationYaml(results, cli.get("out"));
    if (diag.total() > 0) spdlog::info("input diagnostics: {}", diag.summary());
    spdlog::info("wrote {}", cli.get("out"));
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  return 0;
}
