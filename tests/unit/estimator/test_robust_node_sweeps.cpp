/// EstimatorNode on single scenarios of the robustness sweep (issue 8) that once diverged, each
/// against the option or cause that made it diverge (docs/robustness.md).
#include <gtest/gtest.h>

#include <iostream>

#include "robust_node_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;
using namespace meshnav::estimator::test;

TEST(RobustNode, BaroHeightsKeepAHoverUnderCeilingAnchorsOffTheMirrorImage) {
  // Sweep run161 (seed 2): a hover 1.2 m above the floor under four known anchors on a 3.6 m
  // ceiling, no landed phase, the baro's reference pressure in setup.yaml. From the ranges alone
  // the in-motion alignment placed it at z = 5.5 m, the mirror image across the anchors' plane, and
  // the baro's bias (prior σ 1 m) then absorbed the difference (max error 4.6 m).
  const sim::SimulationOptions so = simulationOptions({193831, sim::TrajectoryKind::Hover, Eigen::Vector3d(8.7, 8.4, 3.9),
                                                      sim::AnchorLayoutKind::Ceiling, 2, 4, 3,
                                                      0.178, 0.123, 0.017, "fc", 40.0});
  const auto r = sim::ScenarioSimulator(so).run();
  ASSERT_TRUE(r.dataset.setup.baro_reference_pressure_pa);
  // The hall (setup flight_volume) rules the mirror image out as well; off here, to test the
  // baro heights alone, and then on with the ranges alone.
  auto runWith = [&](bool use_baro, bool use_volume) {
    EstimatorOptions o;
    o.init.motion_use_baro = use_baro;
    o.flight_volume.enabled = use_volume;
    EstimatorNode node(o, r.dataset.setup);
    const RunResult res = run(node, r.dataset, 10.0, [](EstimatorNode&, Timestamp) {});
    std::cout << (use_baro ? "baro heights" : "ranges only") << (use_volume ? ", flight volume" : "")
              << ": max error after 10 s " << res.max_error_after_m << " m" << std::endl;
    EXPECT_TRUE(node.initialized()) << node.waitingFor();
    return res;
  };
  EXPECT_GT(runWith(false, false).max_error_after_m, 2.0);  // the mirror image
  EXPECT_LT(runWith(true, false).max_error_after_m, 1.0);
  EXPECT_LT(runWith(false, true).max_error_after_m, 1.0);  // the mirror image is above the ceiling
}

TEST(RobustNode, StillnessZuptsLetASmoothHoverDrift) {
  // Sweep run123 (seed 2): a 90 s hover with no flight state and no vibration, so the IMU looks
  // still to the StillnessDetector while the body drifts at up to 0.12 m/s. Zero-velocity updates
  // with the flight-state σ (0.02 m/s) pinned the velocity at zero: range NIS 4–8× expected, the
  // IMU noise scale at its cap and a 1.34 m excursion with the generic bias prior (0.64 m with
  // the tactical grade's from setup.yaml). With the stillness σ the drift is allowed (0.22 m).
  // No rotor vibration (the sweep of the incident had none): the hover must read like rest.
  const sim::SimulationOptions so = simulationOptions({706317, sim::TrajectoryKind::Hover, Eigen::Vector3d(11.5, 8.6, 4.2),
                                                      sim::AnchorLayoutKind::Random, 3, 4, 2,
                                                      0.127, 0.103, 0.043, "tactical", 90.0, 0.0});
  const auto r = sim::ScenarioSimulator(so).run();
  ASSERT_TRUE(r.dataset.flight_states.empty());
  auto runWith = [&](double sigma_vel_m_s, double sigma_gyro_rad_s) {
    EstimatorOptions o;
    o.zupt.stillness_sigma_vel_m_s = sigma_vel_m_s;
    o.zupt.stillness_sigma_gyro_rad_s = sigma_gyro_rad_s;
    EstimatorNode node(o, r.dataset.setup);
    const RunResult res = run(node, r.dataset, 10.0, [](EstimatorNode&, Timestamp) {});
    std::cout << "stillness sigma " << sigma_vel_m_s << " m/s: max error after 10 s " << res.max_error_after_m
              << " m, zupts gated " << node.diagnostics().get("gated_zupt") << std::endl;
    EXPECT_TRUE(node.initialized()) << node.waitingFor();
    return res;
  };
  const EstimatorOptions defaults;
  // The flight-state σ of the incident: v 0.02 m/s, ω 0.01 rad/s. Since the ω row fuses the mean
  // reading, zupt.sigma_gyro_rad_s is a rest allowance (default 0.001 rad/s); with it this hover's
  // tight ZUPTs happen to be χ²-gated nearly all (330) and the run ends 0.26 m off, with 0.003 rad/s
  // 4.4 m off: the flight-state velocity σ on a drifting body stays wrong either way. Since the
  // NLOS mixture's update is its collapsed posterior (2026-12-06) the tight σ ends 0.476 m off
  // (above 0.5 m before) against 0.220 m with the stillness σ: still twice as far.
  const double tight = runWith(defaults.zupt.sigma_vel_m_s, 0.01).max_error_after_m;
  const double stated =
      runWith(defaults.zupt.stillness_sigma_vel_m_s, defaults.zupt.stillness_sigma_gyro_rad_s).max_error_after_m;
  EXPECT_GT(tight, 2.0 * stated);
  EXPECT_LT(stated, 0.3);
}

TEST(RobustNode, TheImuGradesBiasSpreadKeepsAOneTagTakeOffUnderClusteredCeilingAnchors) {
  // Sweep run028 (seed 2): a helix with one tag, 7 tag ranges per second, four known anchors
  // clustered on a 6.8 m ceiling, a tactical-grade IMU (switch-on acc bias σ 0.01 m/s²). With the
  // generic prior (σ_ba 0.2 m/s²) the ZUPTs at rest cannot tell tilt from bias, the horizontal
  // position σ grows 0.3 m per second after take-off and the weak ranges let it run 1.2 m off.
  const sim::SimulationOptions so = simulationOptions({266946, sim::TrajectoryKind::Helix, Eigen::Vector3d(6.2, 6.5, 6.8),
                                                      sim::AnchorLayoutKind::Ceiling, 1, 4, 3,
                                                      0.178, 0.061, 0.034, "tactical", 90.0});
  const auto r = sim::ScenarioSimulator(so).run();
  ASSERT_TRUE(r.dataset.setup.noise.imu_acc_bias_sigma);
  EXPECT_DOUBLE_EQ(*r.dataset.setup.noise.imu_acc_bias_sigma, 0.01);
  auto runWith = [&](bool datasheet) {
    SystemSetup setup = r.dataset.setup;
    if (!datasheet) setup.noise.imu_acc_bias_sigma = setup.noise.imu_gyro_bias_sigma = std::nullopt;
    EstimatorNode node(EstimatorOptions{}, setup);
    const RunResult res = run(node, r.dataset, 10.0, [](EstimatorNode&, Timestamp) {});
    std::cout << (datasheet ? "grade's bias spread" : "generic bias prior") << ": max error after 10 s "
              << res.max_error_after_m << " m" << std::endl;
    return res;
  };
  EXPECT_GT(runWith(false).max_error_after_m, 1.0);
  EXPECT_LT(runWith(true).max_error_after_m, 0.8);
}

TEST(RobustNode, NlosOutliersDoNotTriggerAWrongReAlignment) {
  // 30 % NLOS ranges (+0.5 to +3 m) and 20 % drops, a spiral in a 9 × 8 × 5 m hall: a third of the
  // ranges are gated, so the health is `degraded` most of the time. The re-alignment from those
  // ranges disagreed with a filter that was right (0.04–0.14 m) and replaced it eight times,
  // 2–5 m off each time (max error 5.2 m). Gating alone with fitting accepted ranges no longer
  // triggers it.
  const sim::SimulationOptions so = simulationOptions({16, sim::TrajectoryKind::Spiral, Eigen::Vector3d(9.0, 8.0, 5.0),
                                                      sim::AnchorLayoutKind::Paper, 2, 5, 0,
                                                      0.15, 0.3, 0.2, "fc", 90.0});
  const auto r = sim::ScenarioSimulator(so).run();
  EstimatorNode node(EstimatorOptions{}, r.dataset.setup);
  const RunResult res = run(node, r.dataset, 10.0, [](EstimatorNode&, Timestamp) {});
  std::cout << "max error after 10 s " << res.max_error_after_m << " m, recoveries "
            << node.diagnostics().get("recovery") << ", degraded " << node.diagnostics().get("health_degraded")
            << std::endl;
  EXPECT_GT(node.diagnostics().get("health_degraded"), 0);  // the outliers are seen
  EXPECT_EQ(node.diagnostics().get("recovery"), 0);
  EXPECT_LT(res.max_error_after_m, 0.5);
}

TEST(RobustNode, TheFirstRangesAfterARangeGapAreCrossCheckedBeforeTheyAreFused) {
  // docs/robustness.md "Range gaps": no range for 10 s, the IMU carries the pose (3σ grows to
  // about 1.7 m), then NLOS ranges among the first ones after the gap. Each passes its own χ²
  // gate against the wide prior and pulls the estimate; held for 0.5 s and tested against each
  // other (ReentryCheck) they are found and left out.
  const sim::SimulationOptions so = simulationOptions({4242, sim::TrajectoryKind::Figure8, Eigen::Vector3d(10, 8, 5),
                                                      sim::AnchorLayoutKind::Walls, 3, 4, 0,
                                                      0.12, 0.0, 0.0, "fc", 80.0});
  auto r = sim::ScenarioSimulator(so).run();
  Dataset& ds = r.dataset;
  std::erase_if(ds.ranges, [](const RangeSample& s) { return s.t.sec() >= 50.0 && s.t.sec() < 60.0; });
  int n_tag_ranges = 0, n_nlos = 0;
  for (RangeSample& s : ds.ranges) {
    if (s.t.sec() < 60.0 || !(ds.setup.isTag(s.id_initiator) || ds.setup.isTag(s.id_responder))) continue;
    if (ds.setup.isTag(s.id_initiator) && ds.setup.isTag(s.id_responder)) continue;
    if (++n_tag_ranges > 12) break;
    if (n_tag_ranges % 3 == 1) {  // the 1st, 4th, 7th and 10th tag–anchor range: 1.2 m too long
      s.range_m += 1.2;
      s.range_corr_m += 1.2;
      ++n_nlos;
    }
  }
  ASSERT_EQ(n_nlos, 4);
  // Error at the end of the gap (dead-reckoned), largest in 60–63 s and in 60.6–63 s (after the hold).
  struct Errors {
    double at_gap_end_m = 0.0, max_m = 0.0, max_after_hold_m = 0.0;
    int64_t rejected = 0, recoveries = 0;
  };
  auto runWith = [&](double gap_s) {
    EstimatorOptions o;
    o.uwb.reentry_gap_s = gap_s;
    EstimatorNode node(o, ds.setup);
    Errors err;
    size_t gi = 0;
    for (const auto& in : mergeInTimeOrder(ds)) {
      node.onInput(in);
      const Timestamp t = inputTime(in);
      if (!node.initialized() || !std::holds_alternative<ImuSample>(in) || t.sec() < 59.9 || t.sec() > 63.0) continue;
      while (gi + 1 < ds.ground_truth.size() && ds.ground_truth[gi + 1].t <= t) ++gi;
      const double e = (node.pose()->p_IinG - ds.ground_truth[gi].p_IinG).norm();
      if (t.sec() < 60.0) err.at_gap_end_m = e;
      if (t.sec() >= 60.0) err.max_m = std::max(err.max_m, e);
      if (t.sec() >= 60.6) err.max_after_hold_m = std::max(err.max_after_hold_m, e);
    }
    err.rejected = node.diagnostics().get("range_reentry_rejected");
    err.recoveries = node.diagnostics().get("recovery");
    std::cout << "reentry_gap_s " << gap_s << ": error " << err.at_gap_end_m << " m at the end of the gap, max "
              << err.max_m << " m in 60-63 s, " << err.max_after_hold_m << " m in 60.6-63 s; rejected " << err.rejected
              << ", recoveries " << err.recoveries << std::endl;
    EXPECT_TRUE(node.initialized()) << node.waitingFor();
    return err;
  };
  const Errors off = runWith(0.0);
  const Errors on = runWith(EstimatorOptions{}.uwb.reentry_gap_s);
  // Fused one by one, the NLOS ranges pull the dead-reckoned pose further off.
  EXPECT_EQ(off.rejected, 0);
  EXPECT_GT(off.max_m, off.at_gap_end_m + 0.3);
  // Held and cross-checked: they are found, and the others bring the pose back at once.
  EXPECT_GE(on.rejected, 3);
  EXPECT_EQ(on.recoveries, 0);
  EXPECT_LT(on.max_after_hold_m, 0.15);
}

TEST(RobustNode, AConsumerGyroBiasDoesNotAlignAHoverAtAWrongHeight) {
  // Sweep run181 (seed 5): a hover 1.75 m above the floor with a consumer IMU (gyro bias 0.023
  // rad/s) under three known anchors 0.45–1.48 m high (always coplanar), the baro's reference
  // pressure in setup.yaml (bias prior σ 1 m). The in-motion alignment corrected the gyro bias to
  // first order only, so over its 12 s window no fit reached the truth; at t = 12.5 s it took a
  // pose 1.2 m low, and the filter then followed the mirror image (RMSE 1.72 m, ANEES 284, health
  // ok). Integrated again at the fitted bias, every window says what the data says: the pose and
  // its mirror image 1.6–2.1 m away fit alike, so the alignment is refused, not wrong.
  const sim::SimulationOptions so = simulationOptions({339772, sim::TrajectoryKind::Hover, Eigen::Vector3d(8.7, 9.9, 5.6),
                                                      sim::AnchorLayoutKind::Paper, 2, 3, 2,
                                                      0.104, 0.143, 0.037, "consumer", 30.0});
  const auto r = sim::ScenarioSimulator(so).run();
  ASSERT_TRUE(r.dataset.setup.baro_reference_pressure_pa);
  // The hall (setup flight_volume) puts the mirror image out of the running (below the floor):
  // off for the alignment's own behaviour, then on.
  auto runWith = [&](double relinearize_rad, bool use_volume = false) {
    EstimatorOptions o;
    o.init.motion_relinearize_rad = relinearize_rad;
    o.flight_volume.enabled = use_volume;
    EstimatorNode node(o, r.dataset.setup);
    const RunResult res = run(node, r.dataset, 10.0, [](EstimatorNode&, Timestamp) {});
    std::cout << "relinearize " << relinearize_rad << " rad: " << (node.initialized() ? "initialized" : "refused")
              << ", max error after 10 s " << res.max_error_after_m << " m, re-integrations "
              << node.diagnostics().get("init_motion_relinearized") << std::endl;
    return std::make_tuple(node.initialized(), res.max_error_after_m, node.waitingFor());
  };
  const auto [first_order_init, first_order_err, first_order_why] = runWith(0.0);
  EXPECT_TRUE(first_order_init);
  EXPECT_GT(first_order_err, 1.0);
  const auto [init, err, why] = runWith(EstimatorOptions{}.init.motion_relinearize_rad);
  EXPECT_FALSE(init) << "max error after 10 s " << err << " m";
  EXPECT_NE(why.find("ambiguous"), std::string::npos) << why;
  const auto [volume_init, volume_err, volume_why] = runWith(EstimatorOptions{}.init.motion_relinearize_rad, true);
  EXPECT_TRUE(volume_init) << volume_why;
  EXPECT_LT(volume_err, 0.5);  // 0.236 m (2026-11-27)
}

TEST(RobustNode, NlosRangesDoNotPickTheStaticFitOfAHoverUnderNearlyCollinearAnchors) {
  // Sweep run199 (seed 6): a smooth hover (0.07 m/s) that the IMU's stillness takes for rest, two
  // tags 0.32 m apart, four ceiling anchors close to one line (the body 0.55 m off its vertical
  // plane), σ 0.137 m and 10 % NLOS ranges. The static range fit with Huber weights over every
  // range let 6 NLOS ranges among 32 pick one minimum: 1.1 m and 36° from the truth with σ_p
  // 0.37 m, accepted at 5.2 s; the filter then held the heading 21–30° off for 60 s while its σ
  // shrank to 4° (orientation RMSE 23.5°, max error after 10 s 1.03 m, health ok). Found over the
  // inliers alone, the minima are two headings ~70° apart that fit alike: refused until the data
  // fixes the pose.
  // No rotor vibration, as in the sweep of the incident: the stillness must offer the static fit.
  // (With the vibration the hover never reads like rest and no static fit is tried: 1.15 m max
  // error after 10 s, a weakness of its own, docs/faults.md "Flights without flight_state.csv".)
  const sim::SimulationOptions so = simulationOptions({615561, sim::TrajectoryKind::Hover, Eigen::Vector3d(7.4, 10.6, 4.2),
                                                      sim::AnchorLayoutKind::Ceiling, 2, 4, 3,
                                                      0.137, 0.102, 0.001, "tactical", 90.0, 0.0});
  const auto r = sim::ScenarioSimulator(so).run();
  EstimatorNode node(EstimatorOptions{}, r.dataset.setup);
  std::optional<double> t_init;
  const RunResult res = run(node, r.dataset, 10.0, [&](EstimatorNode& n, Timestamp t) {
    if (!t_init && n.initialized()) t_init = t.sec();
  });
  ASSERT_TRUE(t_init);
  std::cout << "initialized at " << *t_init << " s, max error after 10 s " << res.max_error_after_m
            << " m, max angle error " << res.max_angle_error_after_deg << " deg" << std::endl;
  EXPECT_GT(*t_init, 6.0);  // not from the first, NLOS-picked fit
  EXPECT_LT(res.max_error_after_m, 1.0);
  EXPECT_LT(res.max_angle_error_after_deg, 25.0);
}

namespace {

struct OneWallRun {
  RunResult result;
  int side_constraints = 0;  ///< `flight_volume_side_constraint` counter
  int mirrored = 0;          ///< `mirrored_into_flight_volume` counter
};

/// A one-wall scenario with the setup's flight volume used or not.
OneWallRun runOneWall(const sim::SimulationOptions& so, bool use_volume) {
  const auto r = sim::ScenarioSimulator(so).run();
  EXPECT_TRUE(r.dataset.setup.flight_volume) << "the simulator states the hall as the flight volume";
  EstimatorOptions o;
  o.flight_volume.enabled = use_volume;
  EstimatorNode node(o, r.dataset.setup);
  OneWallRun out{run(node, r.dataset, 10.0, [](EstimatorNode&, Timestamp) {}),
                 static_cast<int>(node.diagnostics().get("flight_volume_side_constraint")),
                 static_cast<int>(node.diagnostics().get("mirrored_into_flight_volume"))};
  std::cout << (use_volume ? "flight volume" : "no flight volume") << ": max error after 10 s "
            << out.result.max_error_after_m << " m, side constraints " << out.side_constraints << ", mirrored "
            << out.mirrored << std::endl;
  return out;
}

}  // namespace

TEST(RobustNode, TheFlightVolumeKeepsALawnmowerOffTheMirrorImageBehindOneWallsAnchors) {
  // Sweep run113 (seed 8): three tags on a lawnmower 0.75 m from four known anchors on the wall
  // y = 3 m. Ranges are the same for a position and its mirror image behind the wall, and near the
  // wall they barely tell the two apart: at a turn the estimate slid across (σ_y 0.4 m) and the
  // ranges held it 1.7 m behind the wall, 4.2 m off at worst. With the hall as the setup's flight
  // volume the position is truncated to the hall's side of the anchors' plane: it never slides.
  const sim::SimulationOptions so = simulationOptions({903264, sim::TrajectoryKind::Lawnmower, Eigen::Vector3d(7.3, 6.2, 7.9),
                                                      sim::AnchorLayoutKind::OneWall, 3, 4, 4,
                                                      0.159, 0.081, 0.047, "fc", 90.0});
  EXPECT_GT(runOneWall(so, false).result.max_error_after_m, 2.0);
  const OneWallRun with = runOneWall(so, true);
  EXPECT_LT(with.result.max_error_after_m, 1.0);
  EXPECT_GT(with.side_constraints, 0);
}

TEST(RobustNode, TheFlightVolumeKeepsAOneTagLawnmowerOffTheMirrorImage) {
  // Sweep run050 (seed 4): one tag, three anchors on the wall x = 5.5 m; at a turn 1.05 m from the
  // wall the estimate slid across at 45.4 s and reached 4.7 m (docs/robustness.md, "Crossing the
  // anchors' plane": an alignment check at the crossing only got it to 3.2 m).
  const sim::SimulationOptions so = simulationOptions({57278, sim::TrajectoryKind::Lawnmower, Eigen::Vector3d(11.2, 7.3, 5.4),
                                                      sim::AnchorLayoutKind::OneWall, 1, 3, 3,
                                                      0.196, 0.133, 0.014, "fc", 90.0});
  EXPECT_GT(runOneWall(so, false).result.max_error_after_m, 2.0);
  EXPECT_LT(runOneWall(so, true).result.max_error_after_m, 1.0);
}

TEST(RobustNode, AnEstimateBehindTheAnchorWallIsReflectedIntoTheFlightVolume) {
  // The side constraint off: run113 slides behind the wall and the reflection brings it back
  // (0.96 m at the reflection, measured 2026-11-27; 4.2 m without).
  const sim::SimulationOptions so = simulationOptions({903264, sim::TrajectoryKind::Lawnmower, Eigen::Vector3d(7.3, 6.2, 7.9),
                                                      sim::AnchorLayoutKind::OneWall, 3, 4, 4,
                                                      0.159, 0.081, 0.047, "fc", 90.0});
  const auto r = sim::ScenarioSimulator(so).run();
  EstimatorOptions o;
  o.flight_volume.side_constraint_rate_hz = 0.0;
  EstimatorNode node(o, r.dataset.setup);
  const RunResult res = run(node, r.dataset, 10.0, [](EstimatorNode&, Timestamp) {});
  std::cout << "reflection only: max error after 10 s " << res.max_error_after_m << " m" << std::endl;
  EXPECT_EQ(node.diagnostics().get("flight_volume_side_constraint"), 0);
  EXPECT_GE(node.diagnostics().get("mirrored_into_flight_volume"), 1);
  EXPECT_LT(res.max_error_after_m, 1.2);
  EXPECT_LT(res.final_error_m, 0.5);
}

TEST(RobustNode, TheFlightVolumeLetsAHoverBesideOneWallInitializeInFlight) {
  // Sweep run101 (seed 8): a one-tag hover in an 11.9 m × 6.2 m hall beside four known anchors on
  // one wall, no landed phase. Every alignment window fit the pose and its mirror image behind
  // the wall alike (7.0 m apart), so it never initialized in 90 s. With the hall as the flight
  // volume the mirror image is no candidate (initialized at 60 s there). Flown here for 65 s (the
  // same draws, a shorter flight), which shows the same.
  const sim::SimulationOptions so = simulationOptions({273315, sim::TrajectoryKind::Hover, Eigen::Vector3d(11.9, 6.2, 4.1),
                                                      sim::AnchorLayoutKind::OneWall, 1, 4, 0,
                                                      0.151, 0.084, 0.035, "consumer", 65.0});
  const auto r = sim::ScenarioSimulator(so).run();
  auto runWith = [&](bool use_volume) {
    EstimatorOptions o;
    o.flight_volume.enabled = use_volume;
    EstimatorNode node(o, r.dataset.setup);
    const RunResult res = run(node, r.dataset, 10.0, [](EstimatorNode&, Timestamp) {});
    std::cout << (use_volume ? "flight volume" : "no flight volume") << ": initialized " << node.initialized()
              << ", max error after 10 s " << res.max_error_after_m << " m; " << node.waitingFor() << std::endl;
    EXPECT_EQ(node.initialized(), use_volume);
    return res;
  };
  runWith(false);
  EXPECT_LT(runWith(true).max_error_after_m, 0.5);
}
