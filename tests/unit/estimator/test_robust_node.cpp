/// EstimatorNode robustness on simulated flights (issue 8): recovery from a corrupted pose, IMU
/// gaps on the IMU time line, no landed default without a flight state, no aiding is `lost`,
/// initialization without a landed phase (walk) and refusal while the pose is ambiguous.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <random>

#include "estimator/testing/estimator_node_testing.h"
#include "estimator/node/estimator_node.h"
#include "sim/scenario_simulator.h"
#include "sim/uncertain_anchors.h"
#include "node_test_helpers.h"
#include "robust_node_helpers.h"
#include "tests/support/test_util.h"


using namespace meshnav;
using namespace meshnav::estimator;
using meshnav::estimator::test::run;
using meshnav::estimator::test::RunResult;

namespace {

sim::SimulationResult simulate(uint64_t seed, double duration_s = 80.0) {
  sim::SimulationOptions so;
  so.seed = seed;
  so.duration_scale = duration_s / 140.0;
  return sim::ScenarioSimulator(so).run();
}


/// A hand-held walk without unknown anchors (setup.yaml states its carried height).
sim::SimulationOptions walk(uint64_t seed, const Eigen::Vector3d& hall_m, sim::AnchorLayoutKind layout, int n_known,
                            double duration_s) {
  sim::SimulationOptions so;
  so.seed = seed;
  so.trajectory_kind = sim::TrajectoryKind::Walk;
  so.hall_size_m = hall_m;
  so.anchor_layout = layout;
  so.n_known_anchors = n_known;
  so.n_unknown_anchors = 0;
  so.duration_s = duration_s;
  return so;
}

/// The hand-held walk of several tests: four known anchors on the walls of a 10 × 8 × 3 m hall.
sim::SimulationResult handheldWalk() {
  return sim::ScenarioSimulator(walk(11, Eigen::Vector3d(10, 8, 3), sim::AnchorLayoutKind::Walls, 4, 60.0)).run();
}

}  // namespace

TEST(RobustNode, RecoversFromACorruptedPoseWithinFiveSeconds) {
  const auto r = simulate(3);
  EstimatorNode node(EstimatorOptions{}, r.dataset.setup);
  bool injected = false;
  double back_at = -1.0;
  size_t gi = 0;
  for (const auto& in : mergeInTimeOrder(r.dataset)) {
    node.onInput(in);
    const Timestamp t = inputTime(in);
    if (!injected && t.sec() >= 40.0) {
      EstimatorNodeTesting::injectPoseError(node, Eigen::Vector3d(4.0, 3.0, 0.0), M_PI / 2.0);  // 5 m and 90° of yaw
      injected = true;
    }
    if (!injected || back_at >= 0.0 || !std::holds_alternative<ImuSample>(in)) continue;
    while (gi + 1 < r.dataset.ground_truth.size() && r.dataset.ground_truth[gi + 1].t <= t) ++gi;
    if ((node.pose()->p_IinG - r.dataset.ground_truth[gi].p_IinG).norm() <= 0.3 && node.health() == Health::Ok)
      back_at = t.sec();
  }
  EXPECT_GE(node.diagnostics().get("recovery"), 1);
  ASSERT_GE(back_at, 0.0) << "never back within 0.3 m with health ok";
  std::cout << "back within 0.3 m and ok " << back_at - 40.0 << " s after the corruption" << std::endl;
  EXPECT_LE(back_at - 40.0, 5.0);
  EXPECT_EQ(node.health(), Health::Ok);
  // The ranges after the re-initialization backed it (issue 36: "recovered" is a claim to check).
  EXPECT_GE(node.diagnostics().get("recovery_confirmed"), 1);
  EXPECT_FALSE(node.unconfirmedRecovery());
}

TEST(RobustNode, ImuGapIsDetectedOnTheImuTimeLineAndRecovered) {
  auto r = simulate(4);
  auto& imu = r.dataset.imu;
  imu.erase(std::remove_if(imu.begin(), imu.end(), [](const ImuSample& s) { return s.t.sec() > 40 && s.t.sec() < 43; }),
            imu.end());
  EstimatorNode node(EstimatorOptions{}, r.dataset.setup);
  const RunResult res = run(node, r.dataset, 50.0, [](EstimatorNode&, Timestamp) {});
  EXPECT_EQ(node.diagnostics().get("imu_gap"), 1);
  EXPECT_LT(res.max_error_after_m, 0.6);  // a few seconds after the gap the estimate is back
  EXPECT_EQ(res.final_health, Health::Ok);
  // It is back because the aligned pose is compared with the filter after the gap (47.2 s): the
  // gate alone made it lost only at 50.8 s, 9.6 m off (recovery.after_gap_check_min_s 0).
  EXPECT_EQ(node.diagnostics().get("recovery_after_imu_gap"), 1);
}

// What a gap is propagated on (imu.gap_readings). On a walk, whose tilt swings with every step,
// holding the last reading for 3 s integrates one instant of the gait: the attitude comes out of
// the gap tilted and gravity leaks into the position (36 m). "mean" (the default) continues the
// low-passed acceleration in G and turn rate about the vertical, without tilting: as good as
// assuming the walker still (0.2 m). On the spiral (sequence 4) the turn must go on; there every
// way is metres off right after the gap (held 8.5, mean 9.6, still 12.9 m) and the recovery
// brings it back (the test above).
TEST(RobustNode, AGapIsPropagatedOnTheLowPassedAccelerationAndTurnRate) {
  auto r = handheldWalk();
  auto& imu = r.dataset.imu;
  imu.erase(std::remove_if(imu.begin(), imu.end(), [](const ImuSample& s) { return s.t.sec() > 40 && s.t.sec() < 43; }),
            imu.end());
  auto errorAfterGap = [&](const std::string& mode) {
    EstimatorOptions o;
    o.imu.gap_readings = mode;
    EstimatorNode node(o, r.dataset.setup);
    const RunResult res = run(node, r.dataset, 43.0, [](EstimatorNode&, Timestamp) {});
    EXPECT_EQ(node.diagnostics().get("imu_gap"), 1) << mode;
    EXPECT_NE(res.final_health, Health::Lost) << mode;
    return res.max_error_after_m;
  };
  const double held = errorAfterGap("held"), mean = errorAfterGap("mean"), still = errorAfterGap("still");
  EXPECT_GT(held, 5.0);
  EXPECT_LT(mean, 0.4);
  EXPECT_LT(still, 0.4);
}

TEST(RobustNode, BadGapAndGravityCheckOptionsAreRefusedByName) {
  auto refusal = [](const std::function<void(EstimatorOptions&)>& set) {
    EstimatorOptions o;
    set(o);
    try {
      o.validate();
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refusal([](EstimatorOptions& o) { o.imu.gap_readings = "zero"; }).find("imu.gap_readings"),
            std::string::npos);
  EXPECT_NE(refusal([](EstimatorOptions& o) { o.imu.gap_mean_time_constant_s = 0.0; }).find("gap_mean_time_constant_s"),
            std::string::npos);
  EXPECT_NE(refusal([](EstimatorOptions& o) { o.init.gravity_early_check_nis_ratio = -1.0; })
                .find("init.gravity_early_check_nis_ratio"),
            std::string::npos);
  EXPECT_NE(refusal([](EstimatorOptions& o) { o.recovery.after_gap_check_min_s = -1.0; })
                .find("recovery.after_gap_check_min_s"),
            std::string::npos);
  for (const char* mode : {"mean", "still", "held"})
    EXPECT_EQ(refusal([&](EstimatorOptions& o) { o.imu.gap_readings = mode; }), "accepted") << mode;
}

TEST(RobustNode, WithoutFlightStateNothingIsAssumedLanded) {
  auto r = simulate(5);
  r.dataset.flight_states.clear();
  EstimatorNode node(EstimatorOptions{}, r.dataset.setup);
  const RunResult res = run(node, r.dataset, 10.0, [](EstimatorNode&, Timestamp) {});
  EXPECT_LT(res.max_error_after_m, 0.6);
  EXPECT_EQ(res.final_health, Health::Ok);
  EXPECT_EQ(node.diagnostics().get("recovery"), 0);
}

TEST(RobustNode, NoRangesIsLost) {
  auto r = simulate(6, 40.0);
  r.dataset.ranges.clear();
  EstimatorNode node(EstimatorOptions{}, r.dataset.setup);
  run(node, r.dataset, 0.0, [](EstimatorNode&, Timestamp) {});
  ASSERT_TRUE(node.initialized());  // from initial_pose
  EXPECT_EQ(node.health(), Health::Lost);
  EXPECT_EQ(node.status().health, "lost");
  EXPECT_GE(node.diagnostics().get("health_lost"), 1);
}

TEST(RobustNode, OneTagWithoutPadPriorWaitsForMotionThenStaysConsistent) {
  sim::SimulationOptions so;
  so.seed = 7;
  so.with_initial_pose = false;
  so.n_tags = 1;
  so.duration_scale = 100.0 / 140.0;
  const auto r = sim::ScenarioSimulator(so).run();
  EstimatorNode node(EstimatorOptions{}, r.dataset.setup);
  bool initialized_while_landed = false;
  const RunResult res = run(node, r.dataset, 0.0, [&](EstimatorNode& n, Timestamp t) {
    if (n.initialized() && t.sec() < 4.0) initialized_while_landed = true;
  });
  EXPECT_FALSE(initialized_while_landed) << "yaw is not observable at rest with one tag";
  ASSERT_TRUE(node.initialized()) << node.waitingFor();
  EXPECT_LT(res.max_error_after_m, 1.0);
  EXPECT_NE(node.status().health, "lost");
}

TEST(RobustNode, HandheldWalkInitializesWithoutALandedPhase) {
  const auto r = handheldWalk();
  ASSERT_TRUE(r.dataset.flight_states.empty());
  ASSERT_FALSE(r.dataset.setup.initial_pose);
  EstimatorNode node(EstimatorOptions{}, r.dataset.setup);
  const RunResult res = run(node, r.dataset, 20.0, [](EstimatorNode&, Timestamp) {});
  ASSERT_TRUE(node.initialized()) << node.waitingFor();
  EXPECT_LT(res.max_error_after_m, 0.6);
  EXPECT_NE(res.final_health, Health::Lost);
  // Every in-motion alignment (the refused tries and the one that initialized, plus any recovery
  // or gravity check) ran inside an input's handling and is timed as the step "align".
  const auto steps = node.timings().stats();
  ASSERT_TRUE(steps.count("align"));
  EXPECT_GE(steps.at("align").count, 1 + node.diagnostics().get("init_motion_refused"));
}

// Over LCM the IMU and the ranges come from separate bridges: a range stamped before an IMU sample
// may arrive after it. The first in-motion alignment must not depend on that (an ISAS-Walk1 replay
// over LCM initialized 2 s later than in one process and ended 0.37 m off instead of 0.17 m): before
// the initialization the node releases inputs in the canonical order once every stream has passed
// them (InputSettler), so it fits the same window. With init.settle_max_s = 0 (nothing waits) the
// same arrivals give another estimate: the test can tell.
TEST(RobustNode, TheFirstAlignmentDoesNotDependOnTheOrderInWhichItsStreamsArrive) {
  // The walk from 20 s on: no rest to start from, the in-motion alignment initializes.
  const auto r = handheldWalk();
  std::vector<EstimatorInput> inputs;
  for (const auto& in : mergeInTimeOrder(r.dataset))
    if (inputTime(in).sec() >= 20.0 && inputTime(in).sec() <= 40.0) inputs.push_back(in);
  // Ranges arrive 0–0.3 s late, in their own order (one sender per stream); IMU samples on time.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> lag_s(0.0, 0.3);
  std::vector<std::pair<double, EstimatorInput>> arrivals;
  double last_range_s = -1e9;
  for (const auto& in : inputs) {
    double at_s = inputTime(in).sec();
    if (std::holds_alternative<RangeSample>(in)) last_range_s = at_s = std::max(last_range_s, at_s + lag_s(rng));
    arrivals.emplace_back(at_s, in);
  }
  std::stable_sort(arrivals.begin(), arrivals.end(), [](const auto& a, const auto& b) { return a.first < b.first; });

  auto runWith = [&](double settle_max_s, bool delayed) {
    EstimatorOptions o;
    o.init.settle_max_s = settle_max_s;
    auto node = std::make_unique<EstimatorNode>(o, r.dataset.setup);
    for (size_t i = 0; i < inputs.size(); ++i) node->onInput(delayed ? arrivals[i].second : inputs[i]);
    node->flushHeld();
    return node;
  };
  const auto in_order = runWith(EstimatorOptions{}.init.settle_max_s, false);
  const auto delayed = runWith(EstimatorOptions{}.init.settle_max_s, true);
  ASSERT_TRUE(in_order->initialized() && delayed->initialized());
  // The same tries refused before the same initialization, in motion.
  EXPECT_GT(in_order->diagnostics().get("init_motion_refused"), 0);
  EXPECT_EQ(in_order->diagnostics().get("init_motion_refused"), delayed->diagnostics().get("init_motion_refused"));
  EXPECT_EQ(delayed->diagnostics().get("late_for_initialization"), 0);
  EXPECT_GT(delayed->diagnostics().get("out_of_sequence"), 100);  // after it, rewinds handle them
  EXPECT_LE(estimator::test::stateDifference(*in_order->filter(), *delayed->filter()), 1e-9);
  // Without the wait the same arrivals align on other windows.
  const auto unsettled = runWith(0.0, true);
  ASSERT_TRUE(unsettled->initialized());
  EXPECT_GT(estimator::test::stateDifference(*in_order->filter(), *unsettled->filter()), 1e-6);
}

TEST(RobustNode, CarriedHeightHoldsAWalkUnderThreeNearlyCoplanarAnchors) {
  // Sweep run196 (seed 1): one tag, the three known anchors of the paper layout at 0.30–0.98 m,
  // a walk at 1.1–1.25 m just above their plane. The ranges cannot tell the height from its mirror
  // image across that plane and there is no barometer: without the setup's carried height the
  // aligned height was 1.15 m off and the estimate wandered across the plane (max error 1.43 m).
  sim::SimulationOptions so = walk(475218, Eigen::Vector3d(11.7, 6.1, 3.7), sim::AnchorLayoutKind::Paper, 3, 90.0);
  so.n_tags = 1;
  so.uwb.sigma_range_m = 0.191;
  so.uwb.outlier_fraction = 0.013;
  so.uwb.drop_fraction = 0.027;
  so.imu = sim::ImuNoiseOptions::forGrade("consumer");
  const auto r = sim::ScenarioSimulator(so).run();
  ASSERT_TRUE(r.dataset.setup.carried_height) << "the simulator states the carried height of a walk";
  EXPECT_DOUBLE_EQ(r.dataset.setup.carried_height->height_m, 1.2);
  auto runWith = [&](bool carried) {
    EstimatorOptions o;
    o.carried_height.enabled = carried;
    EstimatorNode node(o, r.dataset.setup);
    const RunResult res = run(node, r.dataset, 10.0, [](EstimatorNode&, Timestamp) {});
    std::cout << (carried ? "carried height" : "no height") << ": max error after 10 s " << res.max_error_after_m
              << " m, updates " << node.diagnostics().get("gated_carried_height") << " gated" << std::endl;
    EXPECT_TRUE(node.initialized()) << node.waitingFor();
    return res;
  };
  const RunResult without = runWith(false);
  const RunResult with = runWith(true);
  EXPECT_GT(without.max_error_after_m, 1.0);  // the case is a real divergence
  EXPECT_LT(with.max_error_after_m, 0.6);
  EXPECT_NE(with.final_health, Health::Lost);
}

TEST(RobustNode, ARealHeightSensorIsIgnoredWhileTheCarriedHeightIsUsed) {
  auto r = sim::ScenarioSimulator(walk(11, Eigen::Vector3d(10, 8, 3), sim::AnchorLayoutKind::Walls, 4, 40.0)).run();
  ASSERT_TRUE(r.dataset.setup.carried_height);
  for (const auto& g : r.dataset.ground_truth) r.dataset.heights.push_back({g.t, g.p_IinG.z() + 5.0});  // way off
  EstimatorNode node(EstimatorOptions{}, r.dataset.setup);
  const RunResult res = run(node, r.dataset, 20.0, [](EstimatorNode&, Timestamp) {});
  ASSERT_TRUE(node.initialized()) << node.waitingFor();
  // Every reading after the initialization (before it, the aligner takes the carried height too).
  EXPECT_GT(node.diagnostics().get("height_ignored_carried_height"), static_cast<int64_t>(r.dataset.heights.size() / 2));
  EXPECT_EQ(node.diagnostics().get("gated_height"), 0);
  EXPECT_LT(res.max_error_after_m, 0.6);
}

TEST(RobustNode, UnderstatedImuNoiseIsScaledUpFromTheRangeInnovations) {
  // An IMU with the white noise of a hand-held rig whose setup.yaml states densities 10× too
  // small (a datasheet figure used in motion): without adaptation the filter trusts dead
  // reckoning and gates the ranges that should correct it; with it the scale grows until the
  // innovations fit (measured with the defaults: max error 2.13 m fixed, 0.49 m adaptive; with
  // the upper bound at 2.8 or 3 instead of 2.2 the growth comes too late here: 1.83 m).
  sim::SimulationOptions so;
  so.seed = 6;
  so.duration_scale = 80.0 / 140.0;
  so.imu.acc_noise_density = 0.06;  // in-use white noise of a hand-held rig (ISAS-Walk1 ≈ 0.07)
  so.imu.gyro_noise_density = 0.006;
  auto r = sim::ScenarioSimulator(so).run();
  const double f = 10.0;
  r.dataset.setup.noise.imu_acc_noise_density = so.imu.acc_noise_density / f;
  r.dataset.setup.noise.imu_gyro_noise_density = so.imu.gyro_noise_density / f;
  r.dataset.setup.noise.imu_acc_bias_rw = so.imu.acc_bias_rw;
  r.dataset.setup.noise.imu_gyro_bias_rw = so.imu.gyro_bias_rw;
  auto runWith = [&](bool adapt, double nlos_fraction) {
    EstimatorOptions o;
    o.process_noise.enabled = adapt;
    o.uwb.nlos_fraction = nlos_fraction;
    o.applySetupNoise(r.dataset.setup.noise);
    EstimatorNode node(o, r.dataset.setup);
    const RunResult res = run(node, r.dataset, 20.0, [](EstimatorNode&, Timestamp) {});
    std::cout << (adapt ? "adaptive" : "fixed") << ": max error after 20 s " << res.max_error_after_m
              << " m, gated " << node.diagnostics().get("gated_range") << ", IMU noise scale "
              << node.processNoiseScale() << std::endl;
    return std::make_pair(res, node.diagnostics().get("gated_range"));
  };
  // The adapter's own figure with Gaussian ranges (ε = 0): 0.517 m (2026-12-06).
  const auto [fixed, gated_fixed] = runWith(false, 0.0);
  const auto [adaptive, gated_adaptive] = runWith(true, 0.0);
  EXPECT_GT(fixed.max_error_after_m, 1.5);  // the case is a real divergence
  EXPECT_LT(adaptive.max_error_after_m, 0.6);
  EXPECT_LT(gated_adaptive, gated_fixed);
  // With the defaults' NLOS mixture the long innovations that the understated noise makes are
  // partly taken as NLOS and weighted down, so the scale grows later: 0.605 m (fixed 8.08 m).
  const auto [mixture_fixed, gated_mixture_fixed] = runWith(false, EstimatorOptions{}.uwb.nlos_fraction);
  const auto [mixture, gated_mixture] = runWith(true, EstimatorOptions{}.uwb.nlos_fraction);
  EXPECT_GT(mixture_fixed.max_error_after_m, 1.5);
  EXPECT_LT(mixture.max_error_after_m, 0.65);
  EXPECT_LT(gated_mixture, gated_mixture_fixed);
}

namespace {
/// The inputs of `ds` from `t0_s` on (a process started at t0 sees nothing earlier).
Dataset from(const Dataset& ds, double t0_s) {
  Dataset out = ds;
  auto cut = [&](auto& v) {
    v.erase(std::remove_if(v.begin(), v.end(), [&](const auto& s) { return s.t.sec() < t0_s; }), v.end());
  };
  cut(out.imu);
  cut(out.baro);
  cut(out.ranges);
  cut(out.flight_states);
  return out;
}
}  // namespace

namespace {
struct RestartResult {
  double first_pose_s = -1.0;
  RunResult run;
  std::map<SensorId, AnchorEstimate> anchors;  ///< at the end
  int64_t resumed = 0;
};

/// The estimator dies at t = 60 s of a paper flight whose anchors 106–110 are estimated (known
/// but uncertain, σ 0.3 m); the new process starts `outage_s` later, from the inputs after that
/// only, with (or without) the checkpoint its predecessor wrote (through the files).
RestartResult restart(const sim::SimulationResult& r, double outage_s, bool with_checkpoint) {
  EstimatorNode before(EstimatorOptions{}, r.dataset.setup);
  for (const auto& in : mergeInTimeOrder(r.dataset)) {
    if (inputTime(in).sec() > 60.0) break;
    before.onInput(in);
  }
  EXPECT_TRUE(before.initialized());
  const meshnav::test::TempDir tmp("checkpoint_test");
  const std::string dir = tmp.string();
  writeCheckpoint(before.checkpoint(), dir);
  EstimatorNode after(EstimatorOptions{}, r.dataset.setup);
  if (with_checkpoint) after.resumeFrom(*readCheckpoint(dir));
  RestartResult res;
  const double t_restart = 60.0 + outage_s;
  res.run = run(after, from(r.dataset, t_restart), t_restart + 10.0, [&](EstimatorNode& n, Timestamp t) {
    if (res.first_pose_s < 0.0 && n.initialized()) res.first_pose_s = t.sec();
  });
  for (const auto& a : after.anchors()) res.anchors[a.id] = a;
  res.resumed = after.diagnostics().get("resumed");
  std::cout << "outage " << outage_s << " s, " << (with_checkpoint ? "with" : "without")
            << " checkpoint: first pose " << res.first_pose_s - t_restart << " s after the restart, max error from "
            << "10 s after it " << res.run.max_error_after_m << " m" << std::endl;
  return res;
}

sim::SimulationResult uncertainAnchorFlight() {
  auto r = simulate(5, 100.0);
  const sim::SimulationOptions so;
  sim::makeAnchorsUncertain(r.dataset, sim::UncertainAnchorOptions{0.3, false, 5}, so.hardware, so.uwb.sigma_range_m);
  return r;
}
}  // namespace

TEST(RobustNode, CheckpointFilesRoundTrip) {
  const auto r = uncertainAnchorFlight();
  EstimatorNode node(EstimatorOptions{}, r.dataset.setup);
  for (const auto& in : mergeInTimeOrder(r.dataset)) {
    if (inputTime(in).sec() > 30.0) break;
    node.onInput(in);
  }
  const EstimatorCheckpoint c = node.checkpoint();
  ASSERT_EQ(c.anchors.size(), 5u);
  const meshnav::test::TempDir tmp("checkpoint_roundtrip");
  const std::string dir = tmp.string();
  writeCheckpoint(c, dir);
  const auto back = readCheckpoint(dir);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->t, c.t);
  EXPECT_NEAR((back->imu.p_IinG - c.imu.p_IinG).norm(), 0.0, 1e-9);
  EXPECT_NEAR(back->imu.q_ItoG.angularDistance(c.imu.q_ItoG), 0.0, 1e-9);
  EXPECT_NEAR((back->cov_imu - c.cov_imu).norm(), 0.0, 1e-12);
  ASSERT_TRUE(back->baro_reference_pa.has_value());
  EXPECT_DOUBLE_EQ(*back->baro_reference_pa, *c.baro_reference_pa);
  ASSERT_EQ(back->anchors.size(), c.anchors.size());
  for (size_t i = 0; i < c.anchors.size(); ++i) {
    EXPECT_EQ(back->anchors[i].id, c.anchors[i].id);
    EXPECT_NEAR((back->anchors[i].cov_p_m2 - c.anchors[i].cov_p_m2).norm(), 0.0, 1e-12);
    EXPECT_EQ(back->anchors[i].biases.size(), c.anchors[i].biases.size());
  }
}

TEST(RobustNode, RestartAfterTheRespawnTimeStillResumesThePose) {
  // A supervisor's respawn (0.2 s delay, about 0.2 s start) plus the checkpoint's age
  // (--state-period 0.1 s): outages up to init.resume_max_outage_s (0.5 s) resume the pose.
  const auto r = uncertainAnchorFlight();
  ASSERT_GE(EstimatorOptions{}.init.resume_max_outage_s, 0.45);
  const RestartResult res = restart(r, 0.45, true);
  EXPECT_EQ(res.resumed, 1);
  EXPECT_LE(res.first_pose_s, 60.45 + 0.01);  // the first IMU sample
  EXPECT_LT(res.run.max_error_after_m, 0.3);
  EXPECT_NE(res.run.final_health, Health::Lost);
}

TEST(RobustNode, RestartAfterAShortOutageResumesThePoseAtOnce) {
  const auto r = uncertainAnchorFlight();
  const RestartResult res = restart(r, 0.1, true);
  EXPECT_EQ(res.resumed, 1);
  EXPECT_LE(res.first_pose_s, 60.1 + 0.01);  // the first IMU sample
  EXPECT_LT(res.run.max_error_after_m, 0.3);
  EXPECT_NE(res.run.final_health, Health::Lost);
}

TEST(RobustNode, RestartAfterALongOutageKeepsTheAnchorsAndReinitializesThePose) {
  // 1 s: the body turned and banked meanwhile (paper spiral); the pose comes from the in-flight
  // alignment, the refined anchors from the checkpoint (not the setup's 0.3 m prior).
  const auto r = uncertainAnchorFlight();
  const RestartResult with = restart(r, 1.0, true), without = restart(r, 1.0, false);
  EXPECT_EQ(with.resumed, 1);
  EXPECT_GT(with.first_pose_s, 0.0);
  EXPECT_LE(with.first_pose_s - 61.0, 4.0);
  EXPECT_LT(with.run.max_error_after_m, 0.3);
  for (SensorId id : {106, 107, 108, 109, 110}) {
    ASSERT_TRUE(with.anchors.count(id)) << id;
    const double err = (with.anchors.at(id).p_AinG - r.dataset.truth->anchor_positions.at(id)).norm();
    EXPECT_LT(err, 0.15) << id;
    // Without the checkpoint the anchor starts again from its setup prior (σ 0.3 m per axis).
    EXPECT_LT(with.anchors.at(id).cov_p_m2.trace(), without.anchors.at(id).cov_p_m2.trace()) << id;
  }
}

TEST(RobustNode, AStaleCheckpointIsNotUsed) {
  auto r = simulate(5, 100.0);
  EstimatorNode before(EstimatorOptions{}, r.dataset.setup);
  for (const auto& in : mergeInTimeOrder(r.dataset)) {
    if (inputTime(in).sec() > 40.0) break;
    before.onInput(in);
  }
  ASSERT_TRUE(before.initialized());
  EstimatorNode later(EstimatorOptions{}, r.dataset.setup);
  later.resumeFrom(before.checkpoint());
  run(later, from(r.dataset, 60.0), 60.0, [](EstimatorNode&, Timestamp) {});  // 20 s > resume_max_age_s
  EXPECT_EQ(later.diagnostics().get("resume_refused"), 1);
  EXPECT_EQ(later.diagnostics().get("resumed"), 0);
}

TEST(RobustNode, MalformedCheckpointIsRefusedNamingFileAndKey) {
  const meshnav::test::TempDir tmp("bad_checkpoint");
  const std::string dir = tmp.string();
  {
    std::ofstream f(dir + "/estimator_state.yaml");
    f << "format: meshnav_estimator_state\nversion: 2\nt: 1.0\nlanded: false\ninstances:\n"
         "  - {kind: imu, id: 1, value: [0, 0, .nan, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0], cov: [1]}\n";
  }
  try {
    readCheckpoint(dir);
    FAIL() << "a NaN position was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("estimator_state.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("instances[0].value"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(readCheckpoint(dir + "/absent").has_value());
}

// The hand-held walk with its anchors given in a frame whose z axis points down (half a turn about
// x, as ISAS-Walk1's RTLS frame): a window after initializing, the node finds gravity along +z of
// that frame, re-initializes with it and then tracks the walk as in the true frame. In the true
// frame nothing is flipped. Without baro (a baro measures along −z and keeps the convention).
// The same upside-down walk, started 20 s late: the node initializes in motion (23 s) from a
// window too short to decide the sign. While undecided the comparison runs each time the data
// since the initialization has doubled (3, 9, 21, 33 s after it, GravityDirection): it decides at
// the second, 26 s, largest error 0.44 m. A fixed step of a window compared at 35 s (0.64–0.69 m);
// the early check on a large range NIS (init.gravity_early_check_nis_ratio) flipped at 32.1 s
// with Gaussian ranges, and with the NLOS mixture (the default) the innovations it watches stay
// below its ratio: it does not fire here, and the schedule does not need it. ISAS-Walk1 started
// late is the real case (realdata.test_realdata_stress).
TEST(RobustNode, AWrongGravityIsFoundEarlyWhenTheRangesSaySo) {
  auto r = handheldWalk();
  r.dataset.baro.clear();
  r.dataset.setup.carried_height.reset();
  const Eigen::Matrix3d R_flip = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  Dataset ds = r.dataset;
  for (auto& [id, p] : ds.setup.abs_anchor_positions) p = R_flip * p;
  for (PoseSample& g : ds.ground_truth) g.p_IinG = R_flip * g.p_IinG;
  ds.setup.flight_volume.reset();
  auto late = [](auto& v) {
    v.erase(std::remove_if(v.begin(), v.end(), [](const auto& x) { return x.t.sec() < 20.0; }), v.end());
  };
  late(ds.imu);
  late(ds.ranges);
  late(ds.ground_truth);
  struct Outcome {
    std::optional<double> flip_s, initialized_s;
    double max_error_m = 0.0;
    int64_t early = 0;
  };
  auto runWith = [&](double nlos_fraction) {
    EstimatorOptions o;
    o.uwb.nlos_fraction = nlos_fraction;
    EstimatorNode node(o, ds.setup);
    Outcome out;
    const RunResult res = run(node, ds, 20.0, [&](EstimatorNode& n, Timestamp t) {
      if (!out.initialized_s && n.initialized()) out.initialized_s = t.sec();
      if (!out.flip_s && n.diagnostics().get("gravity_flip") > 0) out.flip_s = t.sec();
    });
    out.max_error_m = res.max_error_after_m;
    out.early = node.diagnostics().get("gravity_early_check");
    return out;
  };
  const Outcome with_mixture = runWith(EstimatorOptions{}.uwb.nlos_fraction);
  ASSERT_TRUE(with_mixture.initialized_s && with_mixture.flip_s);
  EXPECT_GT(*with_mixture.initialized_s, 22.0);  // in motion, from a short window
  EXPECT_LT(*with_mixture.flip_s - *with_mixture.initialized_s, 9.5);  // by the second comparison
  EXPECT_LT(with_mixture.max_error_m, 0.5);
  EXPECT_EQ(with_mixture.early, 0);
  const Outcome gaussian = runWith(0.0);
  ASSERT_TRUE(gaussian.flip_s);
  EXPECT_LT(*gaussian.flip_s, 33.0);  // the schedule or the early check, whichever comes first
}

TEST(RobustNode, UpsideDownAnchorFrameIsDetectedAndTakenAsItIs) {
  auto r = handheldWalk();
  r.dataset.baro.clear();
  // A carried height is stated above a floor at z = 0 of a z-up frame: without it here.
  r.dataset.setup.carried_height.reset();
  const Eigen::Matrix3d R_flip = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  for (const bool upside_down : {false, true}) {
    Dataset ds = r.dataset;
    if (upside_down) {
      for (auto& [id, p] : ds.setup.abs_anchor_positions) p = R_flip * p;
      for (PoseSample& g : ds.ground_truth) g.p_IinG = R_flip * g.p_IinG;
      if (ds.setup.flight_volume) {  // the hall turns with the frame (y and z negated)
        const FlightVolume v = *ds.setup.flight_volume;
        ds.setup.flight_volume = FlightVolume{Eigen::Vector3d(v.min_m.x(), -v.max_m.y(), -v.max_m.z()),
                                              Eigen::Vector3d(v.max_m.x(), -v.min_m.y(), -v.min_m.z())};
      }
    }
    EstimatorNode node(EstimatorOptions{}, ds.setup);
    const RunResult res = run(node, ds, 35.0, [](EstimatorNode&, Timestamp) {});
    ASSERT_TRUE(node.initialized()) << node.waitingFor();
    EXPECT_EQ(node.diagnostics().get("anchor_frame_z_down"), upside_down ? 1 : 0);
    EXPECT_EQ(node.diagnostics().get("gravity_flip"), upside_down ? 1 : 0);
    EXPECT_LT(res.max_error_after_m, 0.6) << (upside_down ? "upside down" : "true frame");
    EXPECT_NE(res.final_health, Health::Lost);
  }
}
