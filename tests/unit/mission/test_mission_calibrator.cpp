/// The mission config/missions/paper_s2.yaml driving a CalibratorNode on simulated seed 1, wired
/// as in the in-process pipeline (ground-truth poses stand in for the estimator's POSE).
#include <gtest/gtest.h>

#include <cstdio>
#include <deque>
#include <functional>
#include <map>

#include "calibrator/node/calibrator_node.h"
#include "mission/mission_node.h"
#include "sim/scenario_simulator.h"

using namespace meshnav;

namespace {

/// Ground-truth poses of `ds` (as estimates: 1 cm, small attitude covariance) to `on_pose` and its
/// ranges to `calibrator`, in time order (poses first on equal times).
void replayInOrder(const Dataset& ds, calib::CalibratorNode& calibrator,
                   const std::function<void(const PoseEstimate&)>& on_pose) {
  size_t ip = 0, ir = 0;
  while (ip < ds.ground_truth.size() || ir < ds.ranges.size()) {
    if (ir >= ds.ranges.size() || (ip < ds.ground_truth.size() && ds.ground_truth[ip].t <= ds.ranges[ir].t)) {
      PoseEstimate e;
      e.t = ds.ground_truth[ip].t;
      e.p_IinG = ds.ground_truth[ip].p_IinG;
      e.q_ItoG = ds.ground_truth[ip].q_ItoG;
      e.cov_p_m2 = 1e-4 * Eigen::Matrix3d::Identity();
      e.cov_theta_rad2 = 1e-5 * Eigen::Matrix3d::Identity();
      ++ip;
      on_pose(e);
    } else {
      calibrator.onRange(ds.ranges[ir++]);
    }
  }
}

}  // namespace

TEST(MissionWithCalibrator, PaperS2CalibratesFiveAnchorsAtEightyAndHundredSeconds) {
  sim::SimulationOptions so;
  so.seed = 1;
  const auto sim = sim::ScenarioSimulator(so).run();
  const Dataset& ds = sim.dataset;
  ASSERT_TRUE(ds.truth.has_value());

  std::vector<AnchorInit> inits;
  std::vector<MissionStatus> mission_status;
  mission::MissionNode* mission_ptr = nullptr;  // CALIB_STATUS → mission (set once both exist)
  calib::CalibratorSinks cs;
  cs.anchor_init = [&](const AnchorInit& a) { inits.push_back(a); };
  cs.status = [&](const CalibStatus& s) {
    if (mission_ptr) mission_ptr->onCalibStatus(s);
  };
  calib::CalibratorNode calibrator(calib::CalibratorOptions{}, ds.setup, cs);
  mission::MissionSinks ms;
  ms.calib_cmd = [&](const CalibCommand& c) { calibrator.onCommand(c); };
  ms.status = [&](const MissionStatus& s) { mission_status.push_back(s); };
  mission::MissionNode mission(mission::loadMission(std::string(MESHNAV_SOURCE_DIR) + "/config/missions/paper_s2.yaml"),
                               ms);
  mission_ptr = &mission;
  const Timestamp t0 = std::min(ds.ground_truth.front().t, ds.ranges.front().t);
  mission.setT0(t0);

  replayInOrder(ds, calibrator, [&](const PoseEstimate& e) {
    calibrator.onPose(e);
    mission.onPose(e);
  });
  EXPECT_TRUE(mission.finished());
  ASSERT_EQ(inits.size(), 5u);
  for (const auto& a : inits) {
    const double err = (a.p_AinG - ds.truth->anchor_positions.at(a.id)).norm();
    std::printf("anchor %d at %.2f s: error %.3f m, %zu references\n", a.id, a.t.sec(), err, a.biases.size());
    EXPECT_LT(err, 0.3) << a.id;
    EXPECT_NEAR(a.t.sec(), a.id <= 107 ? 80.0 : 100.0, 0.05) << a.id;
  }
  ASSERT_FALSE(mission_status.empty());
  const std::string text = mission_status.back().text;
  EXPECT_NE(text.find("2/2 steps done"), std::string::npos) << text;
  EXPECT_NE(text.find("106 calibrated 107 calibrated 108 calibrated 109 calibrated 110 calibrated"), std::string::npos)
      << text;
}

namespace {

/// What a mission + calibrator run with a late CALIB_STATUS produced.
struct LaggedRun {
  std::map<SensorId, int> inits;  ///< ANCHOR_INIT count per anchor
  double max_error_m = 0.0;
  int64_t resent = 0;             ///< mission: calib_cmd_resent
  int64_t duplicates = 0;         ///< calibrator: CALIB_CMD:duplicate
  int64_t calibrations_ok = 0;
  bool finished = false;
};

/// `mission_yaml` drives a CalibratorNode on `sim` (ground-truth poses), resending unanswered
/// commands every second; every CALIB_STATUS reaches the mission `lag_s` of data time late (a
/// loaded calibrator or link: at 10x replay 1 s of data time is 0.1 s of wall time).
LaggedRun runWithLateStatus(const sim::SimulationResult& sim, const std::string& mission_yaml, double lag_s) {
  const Dataset& ds = sim.dataset;
  LaggedRun out;
  std::deque<CalibStatus> in_flight;
  calib::CalibratorSinks cs;
  cs.anchor_init = [&](const AnchorInit& a) {
    ++out.inits[a.id];
    out.max_error_m = std::max(out.max_error_m, (a.p_AinG - ds.truth->anchor_positions.at(a.id)).norm());
  };
  cs.status = [&](const CalibStatus& s) { in_flight.push_back(s); };
  calib::CalibratorNode calibrator(calib::CalibratorOptions{}, ds.setup, cs);
  mission::MissionSinks ms;
  ms.calib_cmd = [&](const CalibCommand& c) { calibrator.onCommand(c); };
  mission::MissionNodeOptions mo;
  mo.resend_period_s = 1.0;
  mission::MissionNode mission(mission::parseMission(mission_yaml, "lagged.yaml"), ms, mo);
  mission.setT0(std::min(ds.ground_truth.front().t, ds.ranges.front().t));
  replayInOrder(ds, calibrator, [&](const PoseEstimate& e) {
    calibrator.onPose(e);
    while (!in_flight.empty() && e.t >= in_flight.front().t + Duration::fromSec(lag_s)) {
      mission.onCalibStatus(in_flight.front());
      in_flight.pop_front();
    }
    mission.onPose(e);
  });
  out.resent = mission.diagnostics().get("calib_cmd_resent");
  out.duplicates = calibrator.diagnostics().get("CALIB_CMD:duplicate");
  out.calibrations_ok = calibrator.diagnostics().get("calibrations_ok");
  out.finished = mission.finished();
  return out;
}

}  // namespace

TEST(MissionWithCalibrator, LateAnswersCauseResendsButEveryAnchorIsCalibratedExactlyOnce) {
  // A late CALIB_STATUS makes the mission send its commands again (by design: it cannot tell a
  // lost command from a late answer). The requirement: every anchor calibrated (one ANCHOR_INIT,
  // fused once) however late the answers, a re-sent command never undoing a later step. Abort 106
  // at 50 s, collect it anew at 60 s, calibrate it at 80 s: with a 25 s lag the Abort is still
  // being re-sent after the Collect (a stale status still shows 106 collecting).
  sim::SimulationOptions so;
  so.seed = 1;
  const auto sim = sim::ScenarioSimulator(so).run();
  ASSERT_TRUE(sim.dataset.truth.has_value());
  const std::string yaml = R"(collect_at_start: true
steps:
  - {t: 50.0, action: abort, anchors: [106]}
  - {t: 60.0, action: collect, anchors: [106]}
  - {t: 80.0, action: calibrate, anchors: [106, 107]}
  - {t: 100.0, action: calibrate, anchors: [108, 109, 110]}
)";
  for (double lag_s : {0.0, 3.0, 25.0}) {
    SCOPED_TRACE("status lag " + std::to_string(lag_s) + " s");
    const LaggedRun run = runWithLateStatus(sim, yaml, lag_s);
    std::printf("lag %.0f s: %lld resends, %lld duplicates ignored, max error %.3f m\n", lag_s,
                static_cast<long long>(run.resent), static_cast<long long>(run.duplicates), run.max_error_m);
    EXPECT_TRUE(run.finished);
    EXPECT_EQ(run.inits, (std::map<SensorId, int>{{106, 1}, {107, 1}, {108, 1}, {109, 1}, {110, 1}}));
    EXPECT_EQ(run.calibrations_ok, 5);
    EXPECT_LT(run.max_error_m, 0.3);
    EXPECT_EQ(run.duplicates, run.resent);  // in process nothing is lost: every resend is a repeat
    if (lag_s >= 3.0) {
      EXPECT_GT(run.resent, 3);
    }
  }
}
