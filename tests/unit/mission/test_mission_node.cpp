/// Tests of MissionNode: start, steps once and in order at their data times, remove → estimator,
/// t0 handling, time going backwards, status heartbeat and calibrator progress.
#include <gtest/gtest.h>

#include "mission/mission_node.h"

using namespace meshnav;
using namespace meshnav::mission;

namespace {

struct Recorder {
  std::vector<CalibCommand> calib;
  std::vector<EstimatorCommand> est;
  std::vector<MissionStatus> status;
  MissionSinks sinks() {
    MissionSinks s;
    s.calib_cmd = [this](const CalibCommand& c) { calib.push_back(c); };
    s.estimator_cmd = [this](const EstimatorCommand& c) { est.push_back(c); };
    s.status = [this](const MissionStatus& st) { status.push_back(st); };
    return s;
  }
};

Mission paperLike() {
  return parseMission(R"(
steps:
  - {t: 80.0, action: calibrate, anchors: [106, 107]}
  - {t: 100.0, action: calibrate, anchors: [108, 109, 110]}
  - {t: 120.0, action: remove, anchors: [106, 109]}
  - {t: 130.0, action: abort}
)",
                      "test");
}

/// Drives the node with poses at `rate_hz` from t0_s for `duration_s`.
void fly(MissionNode& node, double t0_s, double duration_s, double rate_hz = 50.0) {
  const int n = static_cast<int>(duration_s * rate_hz);
  for (int k = 0; k <= n; ++k) {
    PoseEstimate p;
    p.t = Timestamp::fromSec(t0_s + k / rate_hz);
    node.onPose(p);
  }
}

}  // namespace

TEST(MissionNode, StepsFireOnceInOrderAtTheirDataTimes) {
  Recorder rec;
  MissionNode node(paperLike(), rec.sinks());
  EXPECT_FALSE(node.started());
  const double t0 = 1000.0;  // a dataset that does not start at 0
  fly(node, t0, 150.0);
  ASSERT_TRUE(node.finished());
  ASSERT_EQ(rec.calib.size(), 4u);  // collect-all at start + calibrate + calibrate + abort
  EXPECT_EQ(rec.calib[0].action, CalibCommand::Action::Collect);
  EXPECT_TRUE(rec.calib[0].anchors.empty());
  EXPECT_DOUBLE_EQ(rec.calib[0].t.sec(), t0);
  EXPECT_EQ(rec.calib[1].action, CalibCommand::Action::Calibrate);
  EXPECT_EQ(rec.calib[1].anchors, (std::vector<SensorId>{106, 107}));
  EXPECT_NEAR(rec.calib[1].t.sec(), t0 + 80.0, 1e-6);  // first pose at or after t0 + 80 s
  EXPECT_EQ(rec.calib[2].anchors, (std::vector<SensorId>{108, 109, 110}));
  EXPECT_NEAR(rec.calib[2].t.sec(), t0 + 100.0, 1e-6);
  EXPECT_EQ(rec.calib[3].action, CalibCommand::Action::Abort);
  EXPECT_TRUE(rec.calib[3].anchors.empty());
  EXPECT_NEAR(rec.calib[3].t.sec(), t0 + 130.0, 1e-6);
  ASSERT_EQ(rec.est.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(rec.est[k].action, EstimatorCommand::Action::RemoveInstance);
    EXPECT_NEAR(rec.est[k].t.sec(), t0 + 120.0, 1e-6);
  }
  EXPECT_EQ(rec.est[0].id, 106);
  EXPECT_EQ(rec.est[1].id, 109);
  // Flying on (or again over the same times) runs nothing more.
  fly(node, t0 + 150.0, 20.0);
  fly(node, t0, 150.0);
  EXPECT_EQ(rec.calib.size(), 4u);
  EXPECT_EQ(rec.est.size(), 2u);
  EXPECT_GT(node.diagnostics().get("time_backwards"), 1000);
}

TEST(MissionNode, StepsNotReachedDoNotFireAndAJumpRunsAllDueStepsInOrder) {
  Recorder rec;
  MissionNode node(paperLike(), rec.sinks());
  node.onTime(Timestamp::fromSec(0.0));
  node.onTime(Timestamp::fromSec(79.999));
  EXPECT_EQ(rec.calib.size(), 1u);
  EXPECT_EQ(node.nextStep(), 0u);
  node.onTime(Timestamp::fromSec(125.0));  // past 80, 100 and 120 s at once
  ASSERT_EQ(rec.calib.size(), 3u);
  EXPECT_EQ(rec.calib[1].anchors, (std::vector<SensorId>{106, 107}));
  EXPECT_EQ(rec.calib[2].anchors, (std::vector<SensorId>{108, 109, 110}));
  EXPECT_EQ(rec.est.size(), 2u);
  EXPECT_EQ(node.nextStep(), 3u);
  EXPECT_FALSE(node.finished());
  EXPECT_EQ(node.status().step_index, 2);
  EXPECT_EQ(node.status().n_steps, 4);
}

TEST(MissionNode, SetT0OverridesTheFirstSample) {
  Recorder rec;
  MissionNode node(paperLike(), rec.sinks());
  node.setT0(Timestamp::fromSec(10.0));
  fly(node, 12.0, 78.5);  // first pose 2 s after the first sample (estimator initialisation)
  ASSERT_EQ(rec.calib.size(), 2u);
  EXPECT_NEAR(rec.calib[1].t.sec(), 90.0, 1e-6);  // 10 + 80 s, not 12 + 80 s
  EXPECT_EQ(node.t0()->sec(), 10.0);
  node.setT0(Timestamp::fromSec(0.0));  // ignored after the start
  EXPECT_EQ(node.t0()->sec(), 10.0);
}

TEST(MissionNode, AWrongFirstStampIsRetakenWhenTheClockRebasesBeforeAnyStep) {
  // Left by an audit: the mission's t0 came from the very first data time; when that one was wrong
  // (an hour ahead) the data clock later followed the real stream back, but t0 stayed an hour
  // ahead and no step ever ran (every real time was also counted as going backwards).
  Recorder rec;
  MissionNode node(paperLike(), rec.sinks());
  node.onTime(Timestamp::fromSec(3700.0));  // the wrong first stamp
  ASSERT_EQ(rec.calib.size(), 1u);          // the start's Collect, at the wrong time
  node.onClockRebased(Timestamp::fromSec(100.0));
  EXPECT_EQ(node.diagnostics().get("t0_retaken"), 1);
  EXPECT_EQ(node.t0()->sec(), 100.0);
  ASSERT_EQ(rec.calib.size(), 2u);  // the start's Collect again, at the real time
  EXPECT_EQ(rec.calib[1].action, CalibCommand::Action::Collect);
  EXPECT_DOUBLE_EQ(rec.calib[1].t.sec(), 100.0);
  fly(node, 100.02, 149.0);
  ASSERT_TRUE(node.finished());
  ASSERT_EQ(rec.calib.size(), 5u);
  EXPECT_NEAR(rec.calib[2].t.sec(), 180.0, 1e-6);  // 100 + 80 s
  EXPECT_NEAR(rec.calib[4].t.sec(), 230.0, 1e-6);  // 100 + 130 s
  EXPECT_EQ(node.diagnostics().get("time_backwards"), 0);
}

TEST(MissionNode, APauseOfTheRealStreamBeforeTheFirstStepKeepsT0) {
  // Found by a review of the first version, which re-took t0 whenever no step had run yet: a real
  // stream that pauses 30 s before the first step would have shifted every step by its runtime.
  Recorder rec;
  MissionNode node(paperLike(), rec.sinks());
  fly(node, 0.0, 40.0);
  node.onClockRebased(Timestamp::fromSec(70.0));
  EXPECT_EQ(node.diagnostics().get("t0_retaken"), 0);
  EXPECT_EQ(node.diagnostics().get("clock_rebased"), 1);
  EXPECT_EQ(node.t0()->sec(), 0.0);
  fly(node, 70.02, 15.0);
  ASSERT_EQ(rec.calib.size(), 2u);
  EXPECT_NEAR(rec.calib[1].t.sec(), 80.0, 0.03);  // t0 + 80 s, as without the pause
}

TEST(MissionNode, AStepIssuedAtAWrongFirstStampIsIssuedAgain) {
  Recorder rec;
  MissionNode node(parseMission("steps:\n  - {t: 0.0, action: calibrate, anchors: [106]}\n", "t"), rec.sinks());
  node.onTime(Timestamp::fromSec(3700.0));  // wrong; the step at t0 + 0 runs at once
  ASSERT_EQ(node.nextStep(), 1u);
  node.onClockRebased(Timestamp::fromSec(100.0));
  EXPECT_EQ(node.diagnostics().get("t0_retaken"), 1);
  EXPECT_TRUE(node.finished());
  ASSERT_EQ(rec.calib.size(), 4u);  // Collect, Calibrate at the wrong time; both again at 100 s
  EXPECT_EQ(rec.calib[3].action, CalibCommand::Action::Calibrate);
  EXPECT_DOUBLE_EQ(rec.calib[3].t.sec(), 100.0);
}

TEST(MissionNode, ARebasedClockKeepsAUserT0AndNeverRerunsAStep) {
  {  // t0 given by the user: it stays, and the node follows the new time line
    Recorder rec;
    MissionNode node(paperLike(), rec.sinks());
    node.setT0(Timestamp::fromSec(0.0));
    node.onTime(Timestamp::fromSec(3700.0));  // wrong; with t0 = 0 every step is due
    ASSERT_EQ(rec.calib.size(), 4u);
    node.onClockRebased(Timestamp::fromSec(50.0));
    EXPECT_EQ(node.diagnostics().get("clock_rebased"), 1);
    EXPECT_EQ(node.diagnostics().get("t0_retaken"), 0);
    EXPECT_EQ(node.t0()->sec(), 0.0);
    fly(node, 50.02, 100.0);
    EXPECT_EQ(rec.calib.size(), 4u);  // nothing ran twice
    EXPECT_EQ(node.diagnostics().get("time_backwards"), 0);
    EXPECT_NEAR(node.status().t.sec(), 150.02, 1e-6);  // it follows the new time line
  }
  {  // t0 from the data, but a step already ran: t0 stays, the remaining steps run on time
    Recorder rec;
    MissionNode node(paperLike(), rec.sinks());
    fly(node, 0.0, 90.0);  // the first calibrate at 80 s ran
    ASSERT_EQ(node.nextStep(), 1u);
    node.onClockRebased(Timestamp::fromSec(95.0));  // a jump forward of the whole stream
    EXPECT_EQ(node.diagnostics().get("clock_rebased"), 1);
    EXPECT_EQ(node.t0()->sec(), 0.0);
    EXPECT_EQ(node.nextStep(), 1u);
    fly(node, 95.02, 10.0);
    EXPECT_EQ(node.nextStep(), 2u);  // the second calibrate at t0 + 100 s
    EXPECT_NEAR(rec.calib.back().t.sec(), 100.0, 0.03);
  }
}

TEST(MissionNode, WithoutCollectAtStartAndWithoutSinksNothingBreaks) {
  Mission m = paperLike();
  m.collect_at_start = false;
  Recorder rec;
  MissionNode node(m, rec.sinks());
  node.onTime(Timestamp::fromSec(0.0));
  EXPECT_TRUE(rec.calib.empty());
  MissionNode silent(paperLike());
  fly(silent, 0.0, 140.0);
  EXPECT_TRUE(silent.finished());
  EXPECT_THROW(MissionNode(paperLike(), {}, MissionNodeOptions{0.0}), std::invalid_argument);
}

TEST(MissionNode, StatusAtOneHertzOfDataTimeAndAfterEachStep) {
  Recorder rec;
  MissionNode node(paperLike(), rec.sinks());
  EXPECT_EQ(node.status().text, "waiting for data; estimator not initialized");
  fly(node, 0.0, 60.0);
  EXPECT_EQ(rec.status.size(), 61u);  // 0, 1, ..., 60 s
  EXPECT_EQ(rec.status.back().step_index, -1);
  EXPECT_EQ(rec.status.back().n_steps, 4);
  EXPECT_NE(rec.status.back().text.find("0/4 steps done; next: t=80 s calibrate 106,107"), std::string::npos)
      << rec.status.back().text;
  rec.status.clear();
  fly(node, 60.02, 20.5);  // crosses 80 s: the step's status at 80.0 s (a heartbeat is due there as well)
  EXPECT_EQ(rec.status.size(), 20u);  // 61, ..., 80 s
  EXPECT_EQ(rec.status.back().step_index, 0);

  // Calibrator progress appears in the text.
  EstimatorStatus es;
  es.initialized = true;
  node.onEstimatorStatus(es);
  CalibStatus cs;
  CalibAnchorStatus a;
  a.id = 106, a.state = "calibrated", a.n_ranges = 800;
  cs.anchors.push_back(a);
  a.id = 108, a.state = "collecting", a.n_ranges = 912;
  cs.anchors.push_back(a);
  a.id = 107, a.state = "refused", a.reason = "degenerate_geometry: ...";
  cs.anchors.push_back(a);
  node.onCalibStatus(cs);
  const std::string text = node.status().text;
  EXPECT_NE(text.find("1/4 steps done (last: t=80 s calibrate 106,107); next: t=100 s calibrate 108,109,110"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("calibrator: 106 calibrated 107 refused 108 collecting (912 ranges)"), std::string::npos) << text;
  EXPECT_EQ(text.find("estimator not initialized"), std::string::npos);
}

TEST(MissionNode, CommandsWithoutAnAnswerAreSentAgainUntilTheStatusShowsTheirEffect) {
  // Over a lossy link a CALIB_CMD may be lost: with resend_period_s it is sent again every second
  // of data time until CALIB_STATUS shows its effect.
  Recorder rec;
  MissionNodeOptions o;
  o.resend_period_s = 1.0;
  MissionNode node(paperLike(), rec.sinks(), o);
  auto status = [&](std::vector<std::pair<SensorId, std::string>> states) {
    CalibStatus s;
    for (const auto& [id, st] : states) {
      CalibAnchorStatus a;
      a.id = id;
      a.state = st;
      s.anchors.push_back(a);
    }
    node.onCalibStatus(s);
  };
  node.onTime(Timestamp::fromSec(0.0));
  ASSERT_EQ(rec.calib.size(), 1u);  // collect-all
  node.onTime(Timestamp::fromSec(0.5));
  EXPECT_EQ(rec.calib.size(), 1u);  // not yet due
  node.onTime(Timestamp::fromSec(1.0));
  ASSERT_EQ(rec.calib.size(), 2u);  // lost? sent again, with its issue time: the same command
  EXPECT_EQ(rec.calib[1].action, CalibCommand::Action::Collect);
  EXPECT_DOUBLE_EQ(rec.calib[1].t.sec(), 0.0);
  status({{106, "idle"}, {107, "idle"}});  // a status from before the command: not its effect
  node.onTime(Timestamp::fromSec(2.0));
  EXPECT_EQ(rec.calib.size(), 3u);
  status({{106, "collecting"}, {107, "collecting"}});  // the effect
  node.onTime(Timestamp::fromSec(10.0));
  EXPECT_EQ(rec.calib.size(), 3u);

  node.onTime(Timestamp::fromSec(80.0));  // calibrate 106, 107
  ASSERT_EQ(rec.calib.size(), 4u);
  status({{106, "calibrated"}, {107, "collecting"}});
  node.onTime(Timestamp::fromSec(81.0));
  ASSERT_EQ(rec.calib.size(), 5u);  // 107 not answered yet: the whole command again
  EXPECT_EQ(rec.calib[4].anchors, (std::vector<SensorId>{106, 107}));
  EXPECT_EQ(rec.calib[4].t.us, rec.calib[3].t.us);  // issued at 80 s
  status({{106, "calibrated"}, {107, "refused"}});  // a refusal is an answer
  node.onTime(Timestamp::fromSec(85.0));
  EXPECT_EQ(rec.calib.size(), 5u);
  EXPECT_EQ(node.diagnostics().get("calib_cmd_resent"), 3);

  // Never answered: at most max_resends times.
  Recorder rec2;
  o.max_resends = 3;
  MissionNode lonely(paperLike(), rec2.sinks(), o);
  fly(lonely, 0.0, 20.0);
  EXPECT_EQ(rec2.calib.size(), 4u);  // collect-all and 3 resends
  EXPECT_EQ(lonely.diagnostics().get("calib_cmd_resent"), 3);
}
