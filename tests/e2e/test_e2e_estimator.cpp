/// End to end: simulate the paper scenario (seed 1), run meshnav_run (centralized EKF, DP and DAH;
/// known anchors 101–104 only), and compare estimate.csv with the ground truth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "common/dataset.h"
#include "common/estimate_io.h"

using namespace meshnav;
namespace fs = std::filesystem;

namespace {

int run(const std::string& cmd) {
  std::cout << "$ " << cmd << std::endl;
  return std::system(cmd.c_str());
}

void runAndCheck(const std::string& strategy) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("meshnav_e2e_estimator_" + strategy);
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path data = dir / "seed1", out = dir / "run";
  ASSERT_EQ(run(std::string(MESHNAV_SIM_BIN) + " --seed 1 --out " + data.string() + " > " + (dir / "sim.log").string() +
                " 2>&1"),
            0);
  ASSERT_EQ(run(std::string(MESHNAV_RUN_BIN) + " --strategy " + strategy + " --dataset " + data.string() + " --out " +
                out.string() + " > " +
                (dir / "run.log").string() + " 2>&1"),
            0);
  for (const char* f : {"estimate.csv", "anchors.csv", "timings.csv", "status.txt"})
    EXPECT_TRUE(fs::exists(out / f)) << f;

  Diagnostics diag;
  const auto truth = readTumCsv((data / "groundtruth.csv").string(), diag);
  const auto est = readEstimateCsv((out / "estimate.csv").string(), diag);
  ASSERT_GT(truth.size(), 5000u);
  ASSERT_GT(est.size(), 20000u);
  EXPECT_EQ(diag.total(), 0) << diag.summary();

  // Nearest estimate (IMU rate) to every ground-truth sample.
  double sq_p = 0.0, sq_q = 0.0, nees = 0.0;
  int n = 0;
  size_t j = 0;
  for (const auto& gt : truth) {
    while (j + 1 < est.size() && est[j + 1].t <= gt.t) ++j;
    size_t k = j;
    if (j + 1 < est.size() && (est[j + 1].t - gt.t).us < (gt.t - est[j].t).us) k = j + 1;
    if (std::abs((est[k].t - gt.t).us) > 5000) continue;
    const Eigen::Vector3d dp = est[k].p_IinG - gt.p_IinG;
    const Eigen::AngleAxisd dq(est[k].q_ItoG.conjugate() * gt.q_ItoG);
    sq_p += dp.squaredNorm();
    sq_q += dq.angle() * dq.angle();
    nees += dp.dot(est[k].cov_p_m2.ldlt().solve(dp));
    ++n;
  }
  ASSERT_GT(n, 5000);
  const double rmse_p = std::sqrt(sq_p / n), rmse_q_deg = std::sqrt(sq_q / n) * 180.0 / M_PI;
  const double anees_p = nees / n;
  std::cout << strategy << ", seed 1: position RMSE " << rmse_p << " m, orientation RMSE " << rmse_q_deg
            << " deg, position ANEES " << anees_p << " (" << n << " samples)" << std::endl;
  EXPECT_LE(rmse_p, 0.15);
  // The target: orientation RMSE <= 3 deg.
  EXPECT_LE(rmse_q_deg, 3.0);
  EXPECT_GE(anees_p, 1.0);
  EXPECT_LE(anees_p, 6.0);
}

}  // namespace

TEST(EndToEnd, CentralizedEkfOnSimulatedSeed1) { runAndCheck("centralized"); }
TEST(EndToEnd, DpOnSimulatedSeed1) { runAndCheck("dp"); }
TEST(EndToEnd, DahOnSimulatedSeed1) { runAndCheck("dah"); }
