/// The UWB clock's delay against the IMU clock as a state (estimator/uwb/clock_offset_kind.h) on
/// simulated flights whose range stamps are late (`meshnav_sim --range-time-offset`): the delay is
/// found through the motion, stated in the status, and the error it caused goes; clocks the setup
/// calls one carry no state.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "estimator/testing/estimator_node_testing.h"
#include "robust_node_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;
using namespace meshnav::estimator::test;

namespace {

struct ClockRun {
  double rmse_m = 0.0;       ///< position RMSE after 10 s [m]
  EstimatorStatus status;    ///< at the end
};

/// A figure-eight at walking-to-drone speeds, two tags, four wall anchors, σ 0.10 m, whose ranges
/// are stamped `delay_s` late.
sim::SimulationOptions lateStamps(double delay_s) {
  sim::SimulationOptions so = simulationOptions({4242, sim::TrajectoryKind::Figure8, Eigen::Vector3d(10, 8, 5),
                                                sim::AnchorLayoutKind::Walls, 2, 4, 0, 0.10, 0.0, 0.0, "fc", 60.0});
  so.uwb.time_offset_s = delay_s;
  return so;
}

ClockRun runWith(const Dataset& ds, const EstimatorOptions& o) {
  EstimatorNode node(o, ds.setup);
  const RunResult r = run(node, ds, 10.0, [](EstimatorNode&, Timestamp) {});
  EXPECT_TRUE(node.initialized()) << node.waitingFor();
  return {r.rms_error_after_m > 0.0 ? r.rms_error_after_m : 1e9, node.status()};
}

bool hasClockInstance(const EstimatorStatus& s) {
  for (const auto& i : s.instances)
    if (i.type == "uwb_clock") return true;
  return false;
}

}  // namespace

TEST(ClockOffset, LateStampsAreFoundAndTheirErrorGoes) {
  for (const double delay_s : {0.05, -0.04}) {
    const auto r = sim::ScenarioSimulator(lateStamps(delay_s)).run();
    ASSERT_FALSE(r.dataset.setup.uwb_clock.sigma_s);  // a drawn delay: the estimator's to find
    const ClockRun estimated = runWith(r.dataset, EstimatorOptions{});
    EstimatorOptions blind;
    blind.uwb.clock_offset_sigma_s = 0.0;  // the delay ignored: ranges taken at their stamps
    const ClockRun ignored = runWith(r.dataset, blind);
    const double found = estimated.status.uwb_clock_offset_s, sigma = estimated.status.uwb_clock_offset_sigma_s;
    std::cout << "delay " << delay_s * 1e3 << " ms: found " << found * 1e3 << " ms (σ " << sigma * 1e3
              << " ms); RMSE " << estimated.rmse_m << " m, ignoring it " << ignored.rmse_m << " m" << std::endl;
    EXPECT_TRUE(hasClockInstance(estimated.status));
    EXPECT_FALSE(hasClockInstance(ignored.status));
    EXPECT_NEAR(found, delay_s, 0.01);
    EXPECT_LT(std::abs(found - delay_s), 3.0 * sigma + 0.002);  // consistent with its own σ
    EXPECT_LT(sigma, 0.01);  // the motion made it observable: far below the prior's 0.05 s
    EXPECT_LT(estimated.rmse_m, 0.9 * ignored.rmse_m);
  }
}

TEST(ClockOffset, AReInitializationPutsItBackToItsPrior) {
  // What the offset learnt came through the pose's motion: a pose replaced as wrong takes it along.
  const auto r = sim::ScenarioSimulator(lateStamps(0.05)).run();
  EstimatorNode node(EstimatorOptions{}, r.dataset.setup);
  for (const auto& in : mergeInTimeOrder(r.dataset))
    if (inputTime(in).sec() < 40.0) node.onInput(in);
  ASSERT_TRUE(node.initialized());
  const EstimatorStatus learnt = node.status();
  EXPECT_NEAR(learnt.uwb_clock_offset_s, 0.05, 0.015);
  EXPECT_LT(learnt.uwb_clock_offset_sigma_s, 0.01);
  EstimatorNodeTesting::injectPoseError(node, Eigen::Vector3d(1.0, 0.0, 0.0), 0.2);
  const EstimatorStatus reset = node.status();
  EXPECT_EQ(reset.uwb_clock_offset_s, 0.0);
  EXPECT_DOUBLE_EQ(reset.uwb_clock_offset_sigma_s, EstimatorOptions{}.uwb.clock_offset_sigma_s);
}

TEST(ClockOffset, ClocksTheSetupCallsOneCarryNoState) {
  const auto r = sim::ScenarioSimulator(lateStamps(0.0)).run();
  ASSERT_TRUE(r.dataset.setup.uwb_clock.sigma_s);
  EXPECT_EQ(*r.dataset.setup.uwb_clock.sigma_s, 0.0);
  const ClockRun run = runWith(r.dataset, EstimatorOptions{});
  EXPECT_FALSE(hasClockInstance(run.status));
  EXPECT_EQ(run.status.uwb_clock_offset_s, 0.0);
  EXPECT_EQ(run.status.uwb_clock_offset_sigma_s, 0.0);
}

TEST(ClockOffset, AKnownDelayIsAppliedAsAConstant) {
  const auto r = sim::ScenarioSimulator(lateStamps(0.05)).run();
  Dataset known = r.dataset;
  known.setup.uwb_clock = UwbClock{0.05, 0.0};
  EstimatorOptions blind;
  blind.uwb.clock_offset_sigma_s = 0.0;
  const ClockRun with_constant = runWith(known, blind), ignored = runWith(r.dataset, blind);
  EXPECT_FALSE(hasClockInstance(with_constant.status));
  EXPECT_EQ(with_constant.status.uwb_clock_offset_s, 0.05);
  EXPECT_LT(with_constant.rmse_m, 0.9 * ignored.rmse_m);
}
