/// meshnav_compare_estimates: position RMSE of estimate files against ground truth, and whether a
/// candidate run is within a relative tolerance of a reference run (integration tests).
///   meshnav_compare_estimates --groundtruth GT.csv --reference A/estimate.csv --candidate B/estimate.csv [--tolerance 0.05]
/// Exit 0 when |rmse_B − rmse_A| ≤ tolerance · rmse_A and both cover ≥ 90 % of the reference's rows.
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>

#include "common/cli.h"
#include "common/dataset.h"
#include "common/estimate_io.h"
#include "common/pose_interpolation.h"

namespace {

struct Rmse {
  double rmse_m = 0.0;
  size_t n = 0;
};

Rmse positionRmse(const std::vector<meshnav::PoseSample>& gt, const std::vector<meshnav::PoseEstimate>& est) {
  double sum = 0.0;
  Rmse r;
  for (const auto& e : est) {
    const auto g = meshnav::interpolatePose(gt, e.t);
    if (!g) continue;
    sum += (e.p_IinG - g->p_IinG).squaredNorm();
    ++r.n;
  }
  r.rmse_m = r.n ? std::sqrt(sum / static_cast<double>(r.n)) : NAN;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace meshnav;
  Cli cli("meshnav_compare_estimates",
          "Position RMSE [m] of both estimate.csv files against the TUM ground truth; exit 0 when the candidate's "
          "RMSE is within --tolerance of the reference's.");
  std::string gt_path, ref_path, cand_path;
  double tol = 0.05;
  cli.optional("groundtruth", gt_path, "TUM ground truth")->type_name("FILE")->required();
  cli.optional("reference", ref_path, "reference estimate.csv")->type_name("FILE")->required();
  cli.optional("candidate", cand_path, "candidate estimate.csv")->type_name("FILE")->required();
  cli.option("tolerance", tol, "relative RMSE difference allowed (0.05 = 5 %)")->type_name("F")->check(cli::nonNegative());
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  setupLogging("compare");
  try {
    Diagnostics diag;
    const auto gt = readTumCsv(gt_path, diag);
    const auto ref = readEstimateCsv(ref_path, diag);
    const auto cand = readEstimateCsv(cand_path, diag);
    const Rmse a = positionRmse(gt, ref), b = positionRmse(gt, cand);
    const double rel = std::abs(b.rmse_m - a.rmse_m) / a.rmse_m;
    std::printf("reference: %zu poses, position RMSE %.4f m\n", a.n, a.rmse_m);
    std::printf("candidate: %zu poses, position RMSE %.4f m\n", b.n, b.rmse_m);
    std::printf("relative difference %.2f %% (tolerance %.1f %%)\n", 100.0 * rel, 100.0 * tol);
    if (a.n == 0 || b.n < 0.9 * static_cast<double>(a.n)) {
      std::printf("FAIL: the candidate covers %zu of the reference's %zu poses\n", b.n, a.n);
      return 1;
    }
    if (!(rel <= tol)) {
      std::printf("FAIL: RMSE differs by more than the tolerance\n");
      return 1;
    }
    std::printf("OK\n");
    return 0;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
}
