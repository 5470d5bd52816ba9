/// meshnav_check_flyby: checks the outputs of a fly-by run (calibrator + mission + estimator over
/// LCM, or meshnav_run) against the simulation's truth (integration test flyby_lcm_test.sh).
///   meshnav_check_flyby --truth truth.yaml --anchor-ids 106,107 [--anchor-init FILE] [--anchors anchors.csv]
///                       [--estimate estimate.csv --groundtruth groundtruth.csv] [--max-anchor-error M]
///                       [--max-rmse M]
/// Each check runs when its files are given and prints its numbers; a failed one prints "FAIL: ..."
/// and makes the exit code 1.
///  - --anchor-init (the calibration YAML, e.g. the logger's anchor_init.yaml or the calibrator's
///    --out-yaml): every listed anchor present, the position of its last entry within
///    --max-anchor-error of truth.yaml (default 0.3 m);
///  - --anchors (the estimator's anchors.csv): every listed anchor has rows at or after its
///    calibration time (from --anchor-init when given), i.e. its instance was created and estimated;
///    the error of its last row is printed (and must be within 2 × --max-anchor-error);
///  - --estimate + --groundtruth: position RMSE ≤ --max-rmse (default 0.15 m).
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "calibrator/calibration_io.h"
#include "common/anchor_init_io.h"
#include "common/cli.h"
#include "common/dataset.h"
#include "common/estimate_io.h"
#include "common/pose_interpolation.h"
#include "common/setup.h"

using namespace meshnav;

int main(int argc, char** argv) {
  Cli cli("meshnav_check_flyby",
          "Checks a fly-by run against truth.yaml (see the file's header); exit 0 when every check passes.");
  std::string truth_path, anchor_init_path, anchors_path, estimate_path, groundtruth_path;
  std::vector<SensorId> ids;
  double max_err = 0.3, max_rmse = 0.15;
  cli.optional("truth", truth_path, "truth.yaml")->type_name("FILE")->required();
  cli.idList("anchor-ids", ids, "anchors to check")->required();
  cli.optional("anchor-init", anchor_init_path, "anchor_init.yaml of the run")->type_name("FILE");
  cli.optional("anchors", anchors_path, "anchors.csv of the run")->type_name("FILE");
  cli.optional("estimate", estimate_path, "estimate.csv of the run")->type_name("FILE");
  cli.optional("groundtruth", groundtruth_path, "groundtruth.csv (with --estimate)")->type_name("FILE");
  cli.option("max-anchor-error", max_err, "largest anchor error [m]")->type_name("M")->check(cli::positive());
  cli.option("max-rmse", max_rmse, "largest position RMSE [m]")->type_name("M")->check(cli::positive());
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  setupLogging("check_flyby");
  int failures = 0;
  auto fail = [&failures](const std::string& what) {
    std::printf("FAIL: %s\n", what.c_str());
    ++failures;
  };
  try {
    const Truth truth = loadTruth(truth_path);
    auto truePos = [&](SensorId id) -> const Eigen::Vector3d* {
      const auto it = truth.anchor_positions.find(id);
      if (it == truth.anchor_positions.end()) return nullptr;
      return &it->second;
    };

    std::map<SensorId, AnchorInit> inits;  // the last one per anchor
    if (!anchor_init_path.empty()) {
      for (const auto& a : readAnchorInitsYaml(anchor_init_path)) inits[a.id] = a;
      for (SensorId id : ids) {
        const auto* truth_p = truePos(id);
        if (!truth_p) {
          fail("anchor " + std::to_string(id) + " is not in " + truth_path);
          continue;
        }
        const auto it = inits.find(id);
        if (it == inits.end()) {
          fail("anchor " + std::to_string(id) + " is not in " + anchor_init_path);
          continue;
        }
        const double err = (it->second.p_AinG - *truth_p).norm();
        std::printf("anchor_init %d: t = %.2f s, error %.3f m, sigma %.3f m, %zu references, %d inliers\n", id,
                    it->second.t.sec(), err, std::sqrt(it->second.cov_p_m2.trace()), it->second.biases.size(),
                    it->second.n_inliers);
        if (!(err < max_err)) fail("anchor " + std::to_string(id) + " initialized " + std::to_string(err) + " m off");
      }
    }

    if (!anchors_path.empty()) {
      Diagnostics diag;
      const auto rows = readAnchorsCsv(anchors_path, diag);
      for (SensorId id : ids) {
        const auto init = inits.find(id);
        const Timestamp since = init != inits.end() ? init->second.t : Timestamp{};
        size_t n = 0;
        const AnchorEstimate* last = nullptr;
        for (const auto& r : rows) {
          if (r.id != id || r.t < since) continue;
          ++n;
          last = &r;
        }
        if (n == 0 || !last) {
          fail("anchors.csv has no rows of anchor " + std::to_string(id) + " after its calibration");
          continue;
        }
        const auto* truth_p = truePos(id);
        const double err = truth_p ? (last->p_AinG - *truth_p).norm() : NAN;
        std::printf("anchors.csv %d: %zu rows from t = %.2f s, last at t = %.2f s, error %.3f m\n", id, n,
                    since.sec(), last->t.sec(), err);
        if (!(err < 2.0 * max_err))
          fail("estimated anchor " + std::to_string(id) + " ends " + std::to_string(err) + " m off");
      }
    }

    if (!estimate_path.empty()) {
      Diagnostics diag;
      const auto gt = readTumCsv(groundtruth_path, diag);
      const auto est = readEstimateCsv(estimate_path, diag);
      double sum = 0.0;
      size_t n = 0;
      for (const auto& e : est) {
        const auto g = interpolatePose(gt, e.t);
        if (!g) continue;
        sum += (e.p_IinG - g->p_IinG).squaredNorm();
        ++n;
      }
      const double rmse = n ? std::sqrt(sum / static_cast<double>(n)) : NAN;
      std::printf("estimate: %zu poses, position RMSE %.4f m (limit %.3f m)\n", n, rmse, max_rmse);
      if (n == 0 || !(rmse <= max_rmse)) fail("position RMSE " + std::to_string(rmse) + " m");
    }
  } catch (const std::exception& e) {
    fail(e.what());
  }
  return failures == 0 ? 0 : 1;
}
