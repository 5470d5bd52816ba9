#include <gtest/gtest.h>

#include <cmath>

#include "common/atmosphere.h"
#include "sim/baro_simulator.h"
#include "sim/spiral_trajectory.h"

using namespace meshnav::sim;
namespace atm = meshnav::atmosphere;

TEST(SimBaroSimulator, PressureToHeightRoundTripGivesTheSensorHeight) {
  const SpiralTrajectory tr(TrajectoryOptions::randomized(3));
  BaroOptions opt;
  opt.reference_pressure_pa = 96800.0;
  const BaroSimulator baro(opt, 3);
  for (double t : {0.0, 20.0, 60.0, 100.0, tr.duration()}) {
    const auto s = tr.evaluate(t);
    const double h_true = (s.p_IinG + s.R_ItoG * opt.p_IP).z();
    EXPECT_NEAR(atm::heightFromPressure(baro.idealPressure(s), opt.reference_pressure_pa), h_true, 1e-6);
  }
  // ≈ 12 Pa per metre near 97 kPa: 3 Pa ≈ 0.25 m.
  EXPECT_NEAR(-3.0 * atm::dHeightDPressure(opt.reference_pressure_pa, opt.reference_pressure_pa), 0.25, 0.03);
}

TEST(SimBaroSimulator, SamplesAt50HzWithConfiguredNoise) {
  const SpiralTrajectory tr(TrajectoryOptions::randomized(3));
  BaroOptions opt;
  const BaroSimulator baro(opt, 4);
  const auto samples = baro.simulate(tr, tr.duration());
  ASSERT_GT(samples.size(), 100u);
  EXPECT_EQ((samples[1].t - samples[0].t).us, 20000);
  double s2 = 0, mean = 0;
  for (const auto& s : samples) {
    const double e = s.pressure_pa - baro.idealPressure(tr.evaluate(s.t.sec()));
    s2 += e * e;
    mean += e;
  }
  const double n = static_cast<double>(samples.size());
  EXPECT_NEAR(std::sqrt(s2 / n), opt.pressure_sigma_pa, 0.1);
  EXPECT_NEAR(mean / n, 0.0, 0.15);
  // Climbing to ~8 m lowers the pressure by ~90 Pa.
  double p_min = 1e9;
  for (const auto& s : samples) p_min = std::min(p_min, s.pressure_pa);
  EXPECT_LT(p_min, samples.front().pressure_pa - 80.0);
}
