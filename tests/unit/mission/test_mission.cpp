/// Tests of the mission file loader: the paper mission, defaults, and errors naming file, line and key.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "mission/mission.h"
#include "tests/support/test_util.h"

using namespace meshnav;
using namespace meshnav::mission;

namespace {

/// The error message of parsing `text` (empty when it parses).
std::string errorOf(const std::string& text, const std::string& source = "m.yaml") {
  try {
    parseMission(text, source);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Mission, PaperS2FileHasTheTwoCalibrationSteps) {
  const Mission m = loadMission(std::string(MESHNAV_SOURCE_DIR) + "/config/missions/paper_s2.yaml");
  EXPECT_TRUE(m.collect_at_start);
  ASSERT_EQ(m.steps.size(), 2u);
  EXPECT_DOUBLE_EQ(m.steps[0].t_s, 80.0);
  EXPECT_EQ(m.steps[0].action, MissionAction::Calibrate);
  EXPECT_EQ(m.steps[0].anchors, (std::vector<SensorId>{106, 107}));
  EXPECT_DOUBLE_EQ(m.steps[1].t_s, 100.0);
  EXPECT_EQ(m.steps[1].action, MissionAction::Calibrate);
  EXPECT_EQ(m.steps[1].anchors, (std::vector<SensorId>{108, 109, 110}));
  EXPECT_GT(m.steps[0].line, 1);
  EXPECT_EQ(m.steps[1].describe(), "t=100 s calibrate 108,109,110");
}

TEST(Mission, StepsAreSortedByTimeStablyAndAnchorsDefaultToAll) {
  const Mission m = parseMission(R"(
collect_at_start: false
steps:
  - {t: 50, action: remove, anchors: [106]}
  - {t: 10, action: collect}
  - {t: 50, action: abort, anchors: []}
  - {t: 20.5, action: calibrate}
)",
                                 "inline");
  EXPECT_FALSE(m.collect_at_start);
  ASSERT_EQ(m.steps.size(), 4u);
  EXPECT_EQ(m.steps[0].action, MissionAction::Collect);
  EXPECT_TRUE(m.steps[0].anchors.empty());
  EXPECT_EQ(m.steps[1].action, MissionAction::Calibrate);
  EXPECT_DOUBLE_EQ(m.steps[1].t_s, 20.5);
  EXPECT_EQ(m.steps[2].action, MissionAction::Remove);  // file order kept at equal times
  EXPECT_EQ(m.steps[3].action, MissionAction::Abort);
  EXPECT_EQ(m.steps[2].line, 4);
  EXPECT_TRUE(parseMission("steps: []", "e").steps.empty());
}

TEST(Mission, ErrorsNameFileLineAndKey) {
  struct Case {
    const char* text;
    const char* expect;  ///< substring of the message
  };
  const Case cases[] = {
      {"stepz: []", "m.yaml:1: unknown key 'stepz'"},
      {"collect_at_start: true", "m.yaml: missing key 'steps'"},
      {"steps: {t: 1}", "m.yaml:1: key 'steps' must be a list"},
      {"steps:\n  - 5", "m.yaml:2: key 'steps[0]' must be a map"},
      {"steps:\n  - {action: calibrate}", "m.yaml:2: key 'steps[0].t' is missing"},
      {"steps:\n  - {t: soon, action: calibrate}", "key 'steps[0].t' must be a number"},
      {"steps:\n  - {t: 1, action: calibrate}\n  - {t: -3, action: collect}", "m.yaml:3: key 'steps[1].t' must be a finite time in [0, 4e12] s"},
      // a time that loads but cannot be added to the first sample's (Duration::fromSec threw later)
      {"steps:\n  - {t: 1e13, action: calibrate}", "m.yaml:2: key 'steps[0].t' must be a finite time in [0, 4e12] s"},
      {"steps:\n  - {t: 1}", "key 'steps[0].action' is missing"},
      {"steps:\n  - {t: 1, action: calbrate}", "key 'steps[0].action' has unknown action 'calbrate'"},
      {"steps:\n  - {t: 1, action: calibrate, anchors: 106}", "key 'steps[0].anchors' must be a list"},
      {"steps:\n  - {t: 1, action: calibrate, anchors: [106, x]}", "key 'steps[0].anchors[1]' must be a positive integer id, got 'x'"},
      {"steps:\n  - {t: 1, action: calibrate, anchors: [0]}", "steps[0].anchors[0]"},
      {"steps:\n  - {t: 1, action: remove}", "key 'steps[0].anchors' is required for action 'remove'"},
      {"steps:\n  - {t: 1, action: calibrate, anchor: [1]}", "m.yaml:2: unknown key 'steps[0].anchor'"},
      {"collect_at_start: maybe\nsteps: []", "key 'collect_at_start' must be true or false"},
      {"steps: [ {t: 1, action: calibrate", "m.yaml:1: YAML syntax error"},
      {"- 1\n- 2", "m.yaml: expected a map"},
      // found by fuzz target mission_yaml: keys that are not plain names threw yaml-cpp's bare
      // "bad conversion" (no file, no line)
      {"steps:\n  - {t: 1.5, action: abort,!anchors: []}", "m.yaml:2: a key of steps[0] is not a plain name"},
      {"[1, 2]: x\nsteps: []", "m.yaml:1: a key of the mission is not a plain name"},
  };
  for (const auto& c : cases) {
    const std::string msg = errorOf(c.text);
    EXPECT_NE(msg.find(c.expect), std::string::npos) << "text:\n" << c.text << "\nmessage: " << msg;
  }
}

TEST(Mission, LoadNamesTheFile) {
  const meshnav::test::TempDir dir("mission_test");
  const std::string path = (dir / "bad.yaml").string();
  std::ofstream(path) << "steps:\n  - {t: 80.0, action: calibrate, anchors: [106]}\n  - {t: 90.0, action: fly}\n";
  try {
    loadMission(path);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":3: key 'steps[1].action'"), std::string::npos) << e.what();
  }
  try {
    loadMission((dir / "missing.yaml").string());
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.yaml: cannot open"), std::string::npos) << e.what();
  }
}

// The closed loop's flight plan (key `flight`, mission/flight_plan.h).
TEST(FlightPlanFile, ParsesAndRefusesWithFileLineAndKey) {
  const auto m = parseMission(
      "steps: []\nflight:\n  pad: [1, 2]\n  speed: 0.4\n  waypoints:\n    - {p: [1, 2, 3], yaw_deg: 10, hold: 2}\n",
      "m.yaml");
  ASSERT_TRUE(m.flight.has_value());
  EXPECT_EQ(m.flight->pad_xy_m, Eigen::Vector2d(1, 2));
  EXPECT_DOUBLE_EQ(m.flight->speed_m_s, 0.4);
  ASSERT_EQ(m.flight->waypoints.size(), 1u);
  EXPECT_EQ(m.flight->waypoints[0].p_IinG, Eigen::Vector3d(1, 2, 3));
  EXPECT_DOUBLE_EQ(m.flight->waypoints[0].hold_s, 2.0);
  const auto refused = [](const std::string& text, const std::string& what) {
    try {
      parseMission(text, "m.yaml");
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("m.yaml:"), std::string::npos) << e.what();
      return;
    }
    ADD_FAILURE() << "accepted: " << text;
  };
  refused("steps: []\nflight:\n  sped: 1\n  waypoints: [{p: [1, 2, 3]}]\n", "flight.sped");
  refused("steps: []\nflight:\n  speed: -1\n  waypoints: [{p: [1, 2, 3]}]\n", "flight.speed");
  refused("steps: []\nflight:\n  waypoints: [{p: [1, 2]}]\n", "flight.waypoints[0].p");
  refused("steps: []\nflight:\n  waypoints: []\n", "flight.waypoints");
  refused("steps: []\nflight:\n  waypoints: [{p: [1, 2, .nan]}]\n", "flight.waypoints[0].p[2]");
}
