/// Unit tests of the LCM-free parts of the `calibrator` and `mission` processes
/// (calibrator/process/calibrator_process_config.h, mission/process/mission_process_config.h):
/// option parsing, config loading, σ_d from setup.yaml, the results file, the mission clock and
/// when a finished mission lets its process exit.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "calibrator/calibration_io.h"
#include "common/anchor_init_io.h"
#include "calibrator/process/calibrator_process_config.h"
#include "mission/mission_node.h"
#include "mission/process/mission_process_config.h"
#include "tests/support/test_util.h"

namespace {

using namespace meshnav;
namespace fs = std::filesystem;

/// A process's options declared on a Cli (plus --lcm-url, which transport::ProcessMain adds in the
/// process) and parsed from `args` (without the program name).
template <class Config>
struct Parsed {
  std::unique_ptr<Cli> cli;
  Config config;
  std::string lcm_url;
  bool ok = false;
  int code = -1;
};
template <class Config, typename Declare>
std::unique_ptr<Parsed<Config>> parse(const std::string& program, Declare declare, std::vector<std::string> args) {
  auto p = std::make_unique<Parsed<Config>>();
  p->cli = std::make_unique<Cli>(program, "usage");
  declare(*p->cli, p->config);
  p->cli->optional("lcm-url", p->lcm_url, "LCM provider");
  p->ok = p->cli->parse(args, p->code);
  return p;
}
auto parseCalibrator(std::vector<std::string> args) {
  return parse<calib::CalibratorProcessConfig>("calibrator", calib::declareCalibratorProcessOptions, std::move(args));
}
auto parseMission(std::vector<std::string> args) {
  return parse<mission::MissionProcessConfig>("mission", mission::declareMissionProcessOptions, std::move(args));
}
/// The config after the parse and loadCalibratorProcessConfig.
calib::CalibratorProcessConfig loaded(const Parsed<calib::CalibratorProcessConfig>& p) {
  calib::CalibratorProcessConfig c = p.config;
  calib::loadCalibratorProcessConfig(c);
  return c;
}
mission::MissionProcessConfig finished(const Parsed<mission::MissionProcessConfig>& p) {
  mission::MissionProcessConfig c = p.config;
  mission::finishMissionProcessConfig(c);
  return c;
}

/// Why a command line is refused: by the parse (exit 2, the message) or after it (`finish` throws);
/// "" when it is accepted.
template <class Config, class Finish>
std::string refusal(const Parsed<Config>& p, Finish finish) {
  if (!p.ok) return p.code == 2 ? p.cli->error() : "";
  try {
    finish(p);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

/// A private temp folder (tests/support/test_util.h) with a file writer.
class FileDir {
 public:
  std::string file(const std::string& name, const std::string& text = "") const {
    const auto p = (dir_ / name).string();
    if (!text.empty()) std::ofstream(p) << text;
    return p;
  }

 private:
  meshnav::test::TempDir dir_{"process_config"};
};

std::string repoFile(const std::string& rel) { return std::string(MESHNAV_SOURCE_DIR) + "/" + rel; }

// ------------------------------------------------------------------------------------ calibrator

TEST(CalibratorProcessConfig, DefaultsWithoutConfig) {
  auto p = parseCalibrator({"--setup", "s.yaml"});
  ASSERT_TRUE(p->ok);
  const auto c = loaded(*p);
  EXPECT_EQ(c.setup_path, "s.yaml");
  EXPECT_TRUE(c.config_path.empty());
  EXPECT_TRUE(c.out_yaml.empty());
  EXPECT_FALSE(c.node.auto_mode);
  EXPECT_DOUBLE_EQ(c.pose_rate_hz, 50.0);
  EXPECT_DOUBLE_EQ(c.heartbeat_s, 1.0);
  EXPECT_FALSE(c.sigma_range_from_config);
}

TEST(CalibratorProcessConfig, AutoOutYamlAndRates) {
  auto p = parseCalibrator(
      {"--setup", "s.yaml", "--auto", "--out-yaml", "o/c.yaml", "--pose-rate", "0", "--heartbeat", "0.2",
                  "--lcm-url", "memq://"});
  ASSERT_TRUE(p->ok);
  const auto c = loaded(*p);
  EXPECT_TRUE(c.node.auto_mode);
  EXPECT_EQ(c.out_yaml, "o/c.yaml");
  EXPECT_DOUBLE_EQ(c.pose_rate_hz, 0.0);
  EXPECT_DOUBLE_EQ(c.heartbeat_s, 0.2);
}

TEST(CalibratorProcessConfig, BadValuesNameTheOption) {
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"--heartbeat", "0"}, {"--heartbeat", "x"}, {"--pose-rate", "-1"}, {"--pose-rate", "nan"}}) {
    auto p = parseCalibrator(args);
    const std::string why = refusal(*p, loaded);
    EXPECT_NE(why.find(args[0]), std::string::npos) << args[0] << " " << args[1] << ": " << why;
  }
}

// --fleet serves every vehicle of a fleet file: it takes the setups from the fleet's datasets, so
// --setup beside it is a contradiction, and --bus names one of the two policies.
TEST(CalibratorProcessConfig, AFleetInsteadOfOneSetup) {
  auto p = parseCalibrator({"--fleet", "f.yaml"});
  ASSERT_TRUE(p->ok);
  EXPECT_EQ(p->config.fleet_path, "f.yaml");
  EXPECT_EQ(p->config.bus, "per-vehicle");
  EXPECT_NE(loaded(*p).toString().find("fleet: f.yaml"), std::string::npos);
  auto both = parseCalibrator({"--fleet", "f.yaml", "--setup", "s.yaml"});
  EXPECT_FALSE(both->ok);
  EXPECT_EQ(both->code, 2);
  auto bad_bus = parseCalibrator({"--fleet", "f.yaml", "--bus", "mixed"});
  EXPECT_FALSE(bad_bus->ok);
  EXPECT_EQ(bad_bus->code, 2);
  auto shared = parseCalibrator({"--fleet", "f.yaml", "--bus", "shared"});
  ASSERT_TRUE(shared->ok);
  EXPECT_EQ(shared->config.bus, "shared");
}

// The fleet's mission: a fleet file and a bus policy; --bus names one of the two.
TEST(MissionProcessConfig, AFleetsMission) {
  auto p = parseMission({"--mission", "m.yaml", "--fleet", "f.yaml"});
  ASSERT_TRUE(p->ok);
  EXPECT_EQ(p->config.fleet_path, "f.yaml");
  EXPECT_EQ(p->config.bus, "per-vehicle");
  EXPECT_NE(finished(*p).toString().find("fleet: f.yaml"), std::string::npos);
  auto bad_bus = parseMission({"--mission", "m.yaml", "--fleet", "f.yaml", "--bus", "each"});
  EXPECT_FALSE(bad_bus->ok);
  EXPECT_EQ(bad_bus->code, 2);
}

TEST(CalibratorProcessConfig, UnknownOptionIsRejected) {
  auto p = parseCalibrator({"--autom"});
  EXPECT_FALSE(p->ok);
  EXPECT_EQ(p->code, 2);
}

TEST(CalibratorProcessConfig, RepoConfigEqualsBuiltInDefaults) {
  auto p = parseCalibrator(
      {"--config", repoFile("config/calibrator.yaml")});
  ASSERT_TRUE(p->ok);
  const auto c = loaded(*p);
  EXPECT_EQ(c.calibrator.toString(), calib::CalibratorOptions{}.toString());
  EXPECT_EQ(c.node.toString(), calib::CalibratorNodeOptions{}.toString());
  EXPECT_FALSE(c.sigma_range_from_config);  // left to setup.yaml on purpose
}

TEST(CalibratorProcessConfig, SigmaRangeFromSetupUnlessConfigured) {
  FileDir dir;
  SystemSetup setup;
  setup.noise.sigma_range_m = 0.17;

  auto p = parseCalibrator({});
  ASSERT_TRUE(p->ok);
  auto c = loaded(*p);
  calib::applySetup(c, setup);
  EXPECT_DOUBLE_EQ(c.calibrator.sigma_range_m, 0.17);

  const auto cfg = dir.file("c.yaml", "calibrator:\n  sigma_range: 0.12\ncalibrator_node:\n  auto_min_ranges: 50\n");
  auto q = parseCalibrator({"--config", cfg});
  ASSERT_TRUE(q->ok);
  auto d = loaded(*q);
  EXPECT_TRUE(d.sigma_range_from_config);
  calib::applySetup(d, setup);
  EXPECT_DOUBLE_EQ(d.calibrator.sigma_range_m, 0.12);
  EXPECT_EQ(d.node.auto_min_ranges, 50);

  SystemSetup no_noise;
  auto e = loaded(*p);
  calib::applySetup(e, no_noise);
  EXPECT_DOUBLE_EQ(e.calibrator.sigma_range_m, calib::CalibratorOptions{}.sigma_range_m);
}

TEST(CalibratorProcessConfig, EitherMapMayBeMissing) {
  FileDir dir;
  auto p = parseCalibrator(
      {"--config", dir.file("n.yaml", "calibrator_node:\n  auto_min_ranges: 50\n")});
  ASSERT_TRUE(p->ok);
  const auto c = loaded(*p);
  EXPECT_EQ(c.node.auto_min_ranges, 50);
  EXPECT_EQ(c.calibrator.toString(), calib::CalibratorOptions{}.toString());
  auto q = parseCalibrator(
      {"--config", dir.file("flat.yaml", "min_measurements: 40\n")});
  ASSERT_TRUE(q->ok);
  const auto d = loaded(*q);
  EXPECT_EQ(d.calibrator.min_measurements, 40);
}

TEST(CalibratorProcessConfig, ConfigErrorsNameFileAndKey) {
  FileDir dir;
  const auto bad = dir.file("bad.yaml", "calibrator_node:\n  auto_min_rangez: 50\n");
  auto p = parseCalibrator({"--config", bad});
  ASSERT_TRUE(p->ok);
  try {
    loaded(*p);
    FAIL() << "accepted an unknown key";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad.yaml"), std::string::npos) << what;
    EXPECT_NE(what.find("auto_min_rangez"), std::string::npos) << what;
  }
  const auto typo = dir.file("typo.yaml", "calibrator:\n  min_measurements: 40\ncalibrator_nodes:\n  auto_mode: true\n");
  auto t = parseCalibrator({"--config", typo});
  ASSERT_TRUE(t->ok);
  try {
    loaded(*t);
    FAIL() << "accepted an unknown top-level key";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("calibrator_nodes"), std::string::npos) << e.what();
  }
  auto q = parseCalibrator({"--config", dir.file("missing.yaml")});
  ASSERT_TRUE(q->ok);
  EXPECT_THROW(loaded(*q), std::runtime_error);
}

TEST(CalibrationYamlWriter, WritesOnChangeAndReadsBack) {
  FileDir dir;
  const auto path = dir.file("sub/calibration.yaml");
  calib::CalibrationYamlWriter w(path);
  ASSERT_TRUE(w.enabled());
  calib::CalibrationResult r;
  r.anchor_id = 106;
  r.status = calib::CalibrationStatus::Ok;
  r.t = Timestamp::fromSec(80.0);
  r.p_AinG = Eigen::Vector3d(-1.7, 0.9, 3.2);
  r.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.01;
  std::vector<calib::CalibrationResult> results{r};
  EXPECT_TRUE(w.update(results, 1));
  EXPECT_FALSE(w.update(results, 1));  // nothing new
  EXPECT_TRUE(w.update(results, 1, true));
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  const auto inits = readAnchorInitsYaml(path);
  ASSERT_EQ(inits.size(), 1u);
  EXPECT_EQ(inits[0].id, 106);
  EXPECT_NEAR(inits[0].p_AinG.x(), -1.7, 1e-9);
  EXPECT_FALSE(calib::CalibrationYamlWriter("").update(results, 2));
}

// --------------------------------------------------------------------------------------- mission

TEST(MissionProcessConfig, Defaults) {
  auto p = parseMission({"--mission", "m.yaml"});
  ASSERT_TRUE(p->ok);
  const auto c = finished(*p);
  EXPECT_EQ(c.mission_path, "m.yaml");
  EXPECT_FALSE(c.t0_s.has_value());
  EXPECT_EQ(c.time_channels, std::vector<std::string>{"RANGE"});
  EXPECT_FALSE(c.stay);
  EXPECT_DOUBLE_EQ(c.linger_s, 10.0);
}

TEST(MissionProcessConfig, T0TimeChannelsStay) {
  auto p = parseMission(
      {"--t0", "0", "--time-from", "RANGE, IMU,RANGE", "--stay", "--linger", "0"});
  ASSERT_TRUE(p->ok);
  const auto c = finished(*p);
  ASSERT_TRUE(c.t0_s.has_value());
  EXPECT_DOUBLE_EQ(*c.t0_s, 0.0);
  EXPECT_EQ(c.time_channels, (std::vector<std::string>{"RANGE", "IMU"}));
  EXPECT_TRUE(c.stay);
  EXPECT_DOUBLE_EQ(c.linger_s, 0.0);

  auto q = parseMission({"--t0", "auto", "--time-from", "none"});
  ASSERT_TRUE(q->ok);
  const auto d = finished(*q);
  EXPECT_FALSE(d.t0_s.has_value());
  EXPECT_TRUE(d.time_channels.empty());
}

TEST(MissionProcessConfig, BadValuesNameTheOption) {
  for (const auto& args : std::vector<std::vector<std::string>>{{"--time-from", "POSE"},
                                                                {"--time-from", "RANGE,GARBAGE"},
                                                                {"--t0", "soon"},
                                                                {"--linger", "-1"},
                                                                {"--heartbeat", "0"},
                                                                {"--status-period", "inf"}}) {
    auto p = parseMission(args);
    const std::string why = refusal(*p, finished);
    EXPECT_NE(why.find(args[0]), std::string::npos) << args[0] << " " << args[1] << ": " << why;
  }
}

TEST(DataClock, PassesOnlyAdvancingTimes) {
  mission::DataClock clock;
  Diagnostics diag;
  EXPECT_FALSE(clock.now().has_value());
  EXPECT_TRUE(clock.advance(Timestamp::fromSec(1.0), diag));   // RANGE
  EXPECT_FALSE(clock.advance(Timestamp::fromSec(0.9), diag));  // a lagging POSE
  EXPECT_FALSE(clock.advance(Timestamp::fromSec(1.0), diag));
  EXPECT_TRUE(clock.advance(Timestamp::fromSec(1.1), diag));
  EXPECT_EQ(*clock.now(), Timestamp::fromSec(1.1));
  EXPECT_EQ(diag.total(), 0);  // lagging times are normal, not bad input
}

CalibStatus calibStatus(int64_t ok, int64_t refused, std::vector<std::pair<SensorId, std::string>> states) {
  CalibStatus s;
  s.counters["calibrations_ok"] = ok;
  s.counters["calibrations_refused"] = refused;
  for (const auto& [id, st] : states) {
    CalibAnchorStatus a;
    a.id = id;
    a.state = st;
    s.anchors.push_back(a);
  }
  return s;
}

mission::Mission paperMission() {
  return mission::parseMission(
      "steps:\n  - {t: 80.0, action: calibrate, anchors: [106, 107]}\n"
      "  - {t: 100.0, action: calibrate, anchors: [108, 109, 110]}\n",
      "test");
}

TEST(MissionCompletion, WaitsForTheAnswerToTheLastCalibrate) {
  mission::MissionCompletion done(paperMission(), 10.0);
  done.onCalibStatus(calibStatus(2, 0, {{106, "calibrated"}, {107, "calibrated"}, {108, "collecting"}}));
  EXPECT_FALSE(done.done(0));  // not finished
  done.onFinished(1'000'000);
  EXPECT_FALSE(done.done(1'000'000));
  // A heartbeat sent before the calibrator handled the command.
  done.onCalibStatus(calibStatus(2, 0, {{108, "collecting"}, {109, "collecting"}, {110, "collecting"}}));
  EXPECT_FALSE(done.done(2'000'000));
  // Handled in part (two of three).
  done.onCalibStatus(calibStatus(4, 0, {{108, "calibrated"}, {109, "calibrated"}, {110, "collecting"}}));
  EXPECT_FALSE(done.answered());
  // Answered: a refusal is an answer too.
  done.onCalibStatus(calibStatus(4, 1, {{108, "calibrated"}, {109, "calibrated"}, {110, "refused"}}));
  EXPECT_TRUE(done.answered());
  EXPECT_TRUE(done.done(2'000'000));
  EXPECT_FALSE(done.timedOut(2'000'000));
}

TEST(MissionCompletion, StaleRefusalIsNotAnAnswer) {
  mission::MissionCompletion done(paperMission(), 10.0);
  done.onCalibStatus(calibStatus(2, 3, {{108, "refused"}, {109, "refused"}, {110, "refused"}}));
  done.onFinished(0);
  done.onCalibStatus(calibStatus(2, 3, {{108, "refused"}, {109, "refused"}, {110, "refused"}}));
  EXPECT_FALSE(done.answered());
  done.onCalibStatus(calibStatus(5, 3, {{108, "calibrated"}, {109, "calibrated"}, {110, "calibrated"}}));
  EXPECT_TRUE(done.answered());
}

TEST(MissionCompletion, LingerBoundsTheWait) {
  mission::MissionCompletion done(paperMission(), 2.0);
  done.onFinished(10'000'000);
  EXPECT_FALSE(done.done(11'000'000));
  EXPECT_TRUE(done.done(12'000'000));
  EXPECT_TRUE(done.timedOut(12'000'000));
}

TEST(MissionCompletion, NothingToWaitForWhenTheLastStepIsNotACalibrate) {
  const auto m = mission::parseMission(
      "steps:\n  - {t: 80.0, action: calibrate}\n  - {t: 90.0, action: remove, anchors: [106]}\n", "test");
  mission::MissionCompletion done(m, 10.0);
  EXPECT_FALSE(done.done(0));
  done.onFinished(0);
  EXPECT_TRUE(done.done(0));
  mission::MissionCompletion empty(mission::parseMission("steps: []\n", "test"), 10.0);
  empty.onFinished(0);
  EXPECT_TRUE(empty.done(0));
}

TEST(MissionCompletion, CalibrateAllWaitsUntilNothingCollects) {
  const auto m = mission::parseMission("steps:\n  - {t: 80.0, action: calibrate}\n", "test");
  mission::MissionCompletion done(m, 10.0);
  done.onFinished(0);
  done.onCalibStatus(calibStatus(1, 0, {{106, "calibrated"}, {107, "collecting"}}));
  EXPECT_FALSE(done.answered());
  done.onCalibStatus(calibStatus(2, 0, {{106, "calibrated"}, {107, "calibrated"}}));
  EXPECT_TRUE(done.answered());
}

}  // namespace

TEST(DataClock, AWrongFirstStampIsFollowedBackAndTheMissionStartsAgain) {
  // The mission process's wiring (mission/process/main.cpp): the clock's rebase goes to the node.
  std::vector<CalibCommand> calib;
  mission::MissionSinks sinks;
  sinks.calib_cmd = [&](const CalibCommand& c) { calib.push_back(c); };
  mission::MissionNode node(mission::parseMission("steps:\n  - {t: 5.0, action: calibrate, anchors: [106]}\n", "t"),
                            sinks);
  mission::DataClock clock;
  Diagnostics diag;
  int rebases = 0;
  auto tick = [&](double t_s) {
    const Timestamp t = Timestamp::fromSec(t_s);
    if (!clock.advance(t, diag)) return;
    rebases += clock.rebased();
    if (clock.rebased())
      node.onClockRebased(t);
    else
      node.onTime(t);
  };
  tick(3700.0);  // wrong: an hour ahead of the data
  for (int i = 0; i <= 1000; ++i) tick(20.0 + 0.01 * i);
  EXPECT_EQ(rebases, 1);
  EXPECT_EQ(diag.get("DATA_TIME:jumped_back"), 1);
  EXPECT_EQ(node.diagnostics().get("t0_retaken"), 1);
  ASSERT_TRUE(node.t0().has_value());
  EXPECT_NEAR(node.t0()->sec(), 20.49, 0.02);  // the rebase after 50 agreeing inputs
  ASSERT_TRUE(node.finished());
  ASSERT_EQ(calib.size(), 3u);  // Collect (wrong time), Collect again, Calibrate
  EXPECT_NEAR(calib[2].t.sec(), node.t0()->sec() + 5.0, 0.011);
}

TEST(DataClock, PassesAdvancingTimesAndRefusesOneFarAheadWithACounter) {
  // Found by an audit: one POSE stamped an hour ahead fired every remaining mission step at once,
  // and every real time after it was "not newer" and dropped without a word.
  mission::DataClock clock;
  Diagnostics diag;
  EXPECT_TRUE(clock.advance(Timestamp::fromSec(100.0), diag));
  EXPECT_TRUE(clock.advance(Timestamp::fromSec(100.5), diag));
  EXPECT_FALSE(clock.advance(Timestamp::fromSec(100.2), diag));  // older: not a new data time
  EXPECT_FALSE(clock.advance(Timestamp::fromSec(3700.0), diag));
  EXPECT_EQ(diag.get("DATA_TIME:time_ahead"), 1);
  EXPECT_TRUE(clock.advance(Timestamp::fromSec(101.0), diag));
  EXPECT_EQ(clock.now()->sec(), 101.0);
  // A real jump of the whole stream (a replay started again later) is followed.
  bool followed = false;
  for (int i = 0; i < 60 && !followed; ++i) followed = clock.advance(Timestamp::fromSec(5000.0 + 0.1 * i), diag);
  EXPECT_TRUE(followed);
  EXPECT_EQ(diag.get("time_rebased"), 1);
  // Lagging times are no bad input unless absurdly old; a replay started again is followed and said.
  EXPECT_FALSE(clock.advance(Timestamp::fromSec(4800.0), diag));
  EXPECT_EQ(diag.get("DATA_TIME:time_behind"), 0);
  followed = false;
  for (int i = 0; i < 60 && !followed; ++i) followed = clock.advance(Timestamp::fromSec(10.0 + 0.1 * i), diag);
  EXPECT_TRUE(followed);
  EXPECT_EQ(diag.get("DATA_TIME:jumped_back"), 1);
}
