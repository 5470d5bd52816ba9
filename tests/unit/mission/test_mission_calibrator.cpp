/// The mission config/missions/paper_s2.yaml driving a CalibratorNode on simulated seed 1, wired
/// as in the in-process pipeline (ground-truth poses stand in for the estimator's POSE).
#include <gtest/gtest.h>

#include <cstdio>

#include "calibrator/node/calibrator_node.h"
#include "mission/mission_node.h"
#include "sim/scenario_simulator.h"

using namespace meshnav;

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
      calibrator.onPose(e);
      mission.onPose(e);
    } else {
      calibrator.onRange(ds.ranges[ir++]);
    }
  }
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
