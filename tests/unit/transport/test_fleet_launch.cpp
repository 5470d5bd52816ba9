/// @file test_fleet_launch.cpp
/// @brief The launch file of a fleet over LCM (transport/fleet_launch.h): exactly which processes
/// it runs, each on its vehicle's prefixed channels and its own LCM bus, and what stops the launch.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "transport/fleet_launch.h"

namespace meshnav::transport {
namespace {

std::vector<std::string> strings(const YAML::Node& n) { return n.as<std::vector<std::string>>(); }

/// The value after `flag` in `args` ("" when absent).
std::string after(const std::vector<std::string>& args, const std::string& flag) {
  for (size_t i = 0; i + 1 < args.size(); ++i)
    if (args[i] == flag) return args[i + 1];
  return "";
}

TEST(FleetLaunch, EveryVehicleRunsItsBridgesAndEstimatorOnItsOwnPrefix) {
  const std::vector<FleetEntry> fleet = {{"v0", "/d/v0"}, {"v1", "/d/v1"}};
  FleetLaunchOptions o;
  o.estimator_config = "/cfg/fleet_scale.yaml";
  o.lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  const YAML::Node y = YAML::Load(fleetLaunchYaml(fleet, o));
  // Each vehicle's bus: the base port + 1 + its index, for every one of its processes.
  const std::map<std::string, std::string> bus = {{"v0", "udpm://239.255.76.67:7668?ttl=0"},
                                                  {"v1", "udpm://239.255.76.67:7669?ttl=0"}};
  EXPECT_EQ(y["name"].as<std::string>(), "fleet");
  std::vector<std::string> names;
  std::map<std::string, YAML::Node> by_name;
  for (const auto& p : y["processes"]) {
    names.push_back(p["name"].as<std::string>());
    by_name.emplace(names.back(), static_cast<const YAML::Node&>(p));
  }
  EXPECT_EQ(names, (std::vector<std::string>{"v0_estimator", "v0_logging", "v0_imu_bridge", "v0_uwb_bridge",
                                             "v1_estimator", "v1_logging", "v1_imu_bridge", "v1_uwb_bridge"}));
  EXPECT_EQ(strings(y["shutdown_after"]),
            (std::vector<std::string>{"v0_imu_bridge", "v0_uwb_bridge", "v1_imu_bridge", "v1_uwb_bridge"}));
  EXPECT_EQ(strings(y["stop_last"]), (std::vector<std::string>{"v0_logging", "v1_logging"}));
  EXPECT_DOUBLE_EQ(y["shutdown_delay"].as<double>(), 2.0);
  for (const std::string v : {"v0", "v1"}) {
    const auto est = strings(by_name.at(v + "_estimator")["args"]);
    EXPECT_EQ(by_name.at(v + "_estimator")["command"].as<std::string>(), "${BIN:-build/bin}/estimator");
    EXPECT_EQ(after(est, "--channel-prefix"), v);
    EXPECT_EQ(after(est, "--setup"), "/d/" + v + "/setup.yaml");
    EXPECT_EQ(after(est, "--config"), "${ESTIMATOR_CONFIG:-/cfg/fleet_scale.yaml}");
    EXPECT_EQ(after(est, "--state-dir"), "${OUT}/" + v + "/estimator_state");
    EXPECT_TRUE(by_name.at(v + "_estimator")["required"].as<bool>());
    EXPECT_EQ(after(est, "--lcm-url"), bus.at(v));
    const auto log = strings(by_name.at(v + "_logging")["args"]);
    EXPECT_EQ(after(log, "--channel-prefix"), v);
    EXPECT_EQ(after(log, "--lcm-url"), bus.at(v));
    EXPECT_EQ(after(log, "--out"), "${OUT}/" + v);
    EXPECT_EQ(after(log, "--channels"), v + "/.*");
    EXPECT_NE(std::find(log.begin(), log.end(), "--yield-cpu"), log.end());
    EXPECT_EQ(std::find(est.begin(), est.end(), "--yield-cpu"), est.end());  // the latency path
    for (const std::string b : {"_imu_bridge", "_uwb_bridge"}) {
      const YAML::Node& p = by_name.at(v + b);
      const auto args = strings(p["args"]);
      EXPECT_EQ(p["command"].as<std::string>(), "${BIN:-build/bin}/" + b.substr(1));
      EXPECT_EQ(after(args, "--channel-prefix"), v);
      EXPECT_EQ(after(args, "--lcm-url"), bus.at(v));
      EXPECT_EQ(after(args, "--dataset"), "/d/" + v);
      EXPECT_EQ(after(args, "--wait-for"), "ESTIMATOR_STATUS");  // the node waits for v/ESTIMATOR_STATUS
      EXPECT_EQ(after(args, "--t0-utime"), "${T0_UTIME}");
      EXPECT_EQ(after(args, "--rate"), "${RATE:-1}");
      EXPECT_NE(std::find(args.begin(), args.end(), "--yield-rt"), args.end());  // the estimator answers first
      EXPECT_FALSE(p["required"]);
    }
  }
}

TEST(FleetLaunch, WithoutLoggingNoLoggerAndNoOutVariable) {
  FleetLaunchOptions o;
  o.logging = false;
  const std::string text = fleetLaunchYaml({{"UAV1", "/d/a"}}, o);
  const YAML::Node y = YAML::Load(text);
  std::vector<std::string> names;
  for (const auto& p : y["processes"]) names.push_back(p["name"].as<std::string>());
  EXPECT_EQ(names, (std::vector<std::string>{"UAV1_estimator", "UAV1_imu_bridge", "UAV1_uwb_bridge"}));
  EXPECT_FALSE(y["stop_last"]);
  EXPECT_EQ(text.find("${OUT}"), std::string::npos);
}

// A calibrator and mission serving one vehicle: its channels only, after its estimator.
TEST(FleetLaunch, CalibratorAndMissionForOneVehicle) {
  FleetLaunchOptions o;
  o.logging = false;
  o.calibrator_for = "v1";
  o.mission = "/d/mission.yaml";
  o.calibrator_config = "/cfg/calibrator.yaml";
  o.lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  const YAML::Node y = YAML::Load(fleetLaunchYaml({{"v0", "/d/v0"}, {"v1", "/d/v1"}}, o));
  std::vector<std::string> names;
  std::map<std::string, std::vector<std::string>> args;
  for (const auto& p : y["processes"]) {
    names.push_back(p["name"].as<std::string>());
    args[names.back()] = strings(p["args"]);
  }
  EXPECT_EQ(names, (std::vector<std::string>{"v0_estimator", "v0_imu_bridge", "v0_uwb_bridge", "v1_estimator",
                                             "v1_calibrator", "v1_mission", "v1_imu_bridge", "v1_uwb_bridge"}));
  EXPECT_EQ(after(args["v1_calibrator"], "--channel-prefix"), "v1");
  EXPECT_EQ(after(args["v1_calibrator"], "--setup"), "/d/v1/setup.yaml");
  EXPECT_EQ(after(args["v1_calibrator"], "--config"), "${CALIBRATOR_CONFIG:-/cfg/calibrator.yaml}");
  EXPECT_EQ(after(args["v1_mission"], "--channel-prefix"), "v1");
  EXPECT_EQ(after(args["v1_mission"], "--mission"), "/d/mission.yaml");
  // On v1's bus (the base URL's port + 2), with v1's estimator: CALIB_CMD, CALIB_STATUS and
  // MISSION_STATUS go there, not to a fleet-wide bus.
  for (const char* p : {"v1_estimator", "v1_calibrator", "v1_mission", "v1_imu_bridge"})
    EXPECT_EQ(after(args[p], "--lcm-url"), "udpm://239.255.76.67:7669?ttl=0") << p;
  EXPECT_EQ(after(args["v0_estimator"], "--lcm-url"), "udpm://239.255.76.67:7668?ttl=0");
  o.calibrator_for = "v7";
  EXPECT_THROW(fleetLaunchYaml({{"v0", "/d/v0"}}, o), std::invalid_argument);
}

// One calibrator for the whole fleet: it opens every vehicle's bus itself from the base URL; so
// does the fleet's mission, which follows the first vehicle (on whose bus the calibrator's
// CALIB_CMD and CALIB_STATUS are) and commands every vehicle.
TEST(FleetLaunch, OneCalibratorForTheFleetAndItsMissionOnTheFirstVehiclesBus) {
  FleetLaunchOptions o;
  o.fleet_calibrator = true;
  o.source = "/d/fleet.yaml";
  o.mission = "/d/mission.yaml";
  o.calibrator_config = "/cfg/calibrator.yaml";
  o.lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  const std::vector<FleetEntry> fleet = {{"a", "/d/a"}, {"b", "/d/b"}};
  const YAML::Node y = YAML::Load(fleetLaunchYaml(fleet, o));
  std::vector<std::string> names;
  std::map<std::string, std::vector<std::string>> args;
  for (const auto& p : y["processes"]) {
    names.push_back(p["name"].as<std::string>());
    args[names.back()] = strings(p["args"]);
  }
  ASSERT_GE(names.size(), 2u);
  EXPECT_EQ(names[0], "fleet_calibrator");  // before the bridges start the data
  EXPECT_EQ(names[1], "fleet_mission");
  EXPECT_EQ(std::count_if(names.begin(), names.end(), [](const std::string& n) { return n.find("calibrator") != std::string::npos; }), 1);
  const auto& c = args["fleet_calibrator"];
  EXPECT_EQ(after(c, "--fleet"), "/d/fleet.yaml");
  EXPECT_EQ(after(c, "--bus"), "per-vehicle");
  EXPECT_EQ(after(c, "--lcm-url"), "udpm://239.255.76.67:7667?ttl=0");  // the base: it derives each bus
  EXPECT_EQ(after(c, "--config"), "${CALIBRATOR_CONFIG:-/cfg/calibrator.yaml}");
  EXPECT_EQ(after(c, "--channel-prefix"), "");
  // Below the estimators: neither the calibrator nor the mission is on the latency path.
  EXPECT_NE(std::find(c.begin(), c.end(), "--yield-cpu"), c.end());
  EXPECT_NE(std::find(args["fleet_mission"].begin(), args["fleet_mission"].end(), "--yield-cpu"),
            args["fleet_mission"].end());
  EXPECT_EQ(after(c, "--state-dir"), "${OUT}/fleet_calibrator_state/${T0_UTIME}");  // a respawn resumes, a new run not
  const auto& m = args["fleet_mission"];  // follows the first vehicle, commands every one
  EXPECT_EQ(after(m, "--fleet"), "/d/fleet.yaml");
  EXPECT_EQ(after(m, "--bus"), "per-vehicle");
  EXPECT_EQ(after(m, "--channel-prefix"), "");
  EXPECT_EQ(after(m, "--lcm-url"), "udpm://239.255.76.67:7667?ttl=0");
  EXPECT_EQ(after(m, "--mission"), "/d/mission.yaml");
  // Without a logger (no OUT) no journal; on a shared bus the calibrator gets the shared URL.
  o.logging = false;
  o.bus = FleetBus::kShared;
  o.mission.clear();
  const YAML::Node shared = YAML::Load(fleetLaunchYaml(fleet, o));
  const auto sc = strings(shared["processes"][0]["args"]);
  EXPECT_EQ(after(sc, "--bus"), "shared");
  EXPECT_EQ(after(sc, "--state-dir"), "");
  EXPECT_NE(shared["processes"][1]["name"].as<std::string>(), "fleet_mission");
  // Refused: with a calibrator for one vehicle, and without the fleet file's path.
  o.calibrator_for = "a";
  EXPECT_THROW(fleetLaunchYaml(fleet, o), std::invalid_argument);
  o.calibrator_for.clear();
  o.source.clear();
  EXPECT_THROW(fleetLaunchYaml(fleet, o), std::invalid_argument);
}

// The fleet's inter-vehicle ranges over LCM: one peer_router for two or more vehicles of a fleet
// file, on the base URL from which it derives each vehicle's bus, at the estimators' priority.
TEST(FleetLaunch, APeerRouterForAFleetOfTwoOrMoreUnlessTurnedOff) {
  FleetLaunchOptions o;
  o.source = "/d/fleet.yaml";
  o.lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  const std::vector<FleetEntry> fleet = {{"a", "/d/a"}, {"b", "/d/b"}};
  auto processes = [&](const std::vector<FleetEntry>& f) {
    std::map<std::string, YAML::Node> by_name;
    for (const auto& p : YAML::Load(fleetLaunchYaml(f, o))["processes"])
      by_name.emplace(p["name"].as<std::string>(), static_cast<const YAML::Node&>(p));
    return by_name;
  };
  const auto with = processes(fleet);
  ASSERT_EQ(with.count("fleet_peer_router"), 1u);
  const YAML::Node& r = with.at("fleet_peer_router");
  EXPECT_EQ(r["command"].as<std::string>(), "${BIN:-build/bin}/peer_router");
  const auto args = strings(r["args"]);
  EXPECT_EQ(after(args, "--fleet"), "/d/fleet.yaml");
  EXPECT_EQ(after(args, "--bus"), "per-vehicle");
  EXPECT_EQ(after(args, "--lcm-url"), "udpm://239.255.76.67:7667?ttl=0");
  EXPECT_EQ(std::find(args.begin(), args.end(), "--yield-cpu"), args.end());  // a vehicle waits on it
  EXPECT_FALSE(r["required"]);  // each vehicle navigates on its anchors without it
  // A respawn takes back whose information each vehicle holds, from this launch's journal only.
  EXPECT_EQ(r["respawn"].as<std::string>(), "on-failure");
  EXPECT_DOUBLE_EQ(r["respawn_delay"].as<double>(), 0.2);  // a vehicle short of anchors waits on it
  EXPECT_EQ(after(args, "--state-dir"), o.logging ? "${OUT}/fleet_peer_router_state/${T0_UTIME}" : "");
  o.logging = !o.logging;
  EXPECT_EQ(after(strings(processes(fleet).at("fleet_peer_router")["args"]), "--state-dir"),
            o.logging ? "${OUT}/fleet_peer_router_state/${T0_UTIME}" : "");
  o.logging = !o.logging;
  EXPECT_EQ(processes({fleet[0]}).count("fleet_peer_router"), 0u);  // one vehicle: no peers
  o.peer_router = false;
  EXPECT_EQ(processes(fleet).count("fleet_peer_router"), 0u);
  o.peer_router = true;
  o.source.clear();  // no fleet file to give it
  EXPECT_EQ(processes(fleet).count("fleet_peer_router"), 0u);
}

// --bus shared: every process on the one URL of the environment (no --lcm-url), or on the one given.
TEST(FleetLaunch, ASharedBusPutsEveryVehicleOnTheBaseUrl) {
  FleetLaunchOptions o;
  o.logging = false;
  o.bus = FleetBus::kShared;
  const std::vector<FleetEntry> fleet = {{"v0", "/d/v0"}, {"v1", "/d/v1"}};
  for (const auto& p : YAML::Load(fleetLaunchYaml(fleet, o))["processes"])
    EXPECT_EQ(after(strings(p["args"]), "--lcm-url"), "") << p["name"].as<std::string>();
  o.lcm_url = "udpm://239.1.2.3:9000?ttl=0";
  for (const auto& p : YAML::Load(fleetLaunchYaml(fleet, o))["processes"])
    EXPECT_EQ(after(strings(p["args"]), "--lcm-url"), o.lcm_url) << p["name"].as<std::string>();
}

// A bus per vehicle needs udpm ports: memq:// and ports past 65535 are refused before any text.
TEST(FleetLaunch, ABusPerVehicleRefusesABaseUrlWithoutPorts) {
  FleetLaunchOptions o;
  o.lcm_url = "memq://";
  EXPECT_THROW(fleetLaunchYaml({{"v0", "/d/v0"}}, o), std::invalid_argument);
  o.lcm_url = "udpm://239.255.76.67:65535";
  EXPECT_THROW(fleetLaunchYaml({{"v0", "/d/v0"}}, o), std::invalid_argument);
}

TEST(FleetLaunch, RefusesANameThatIsNoChannelPrefixAndAnEmptyFleet) {
  EXPECT_THROW(fleetLaunchYaml({{"a/b", "/d"}}, {}), std::invalid_argument);
  EXPECT_THROW(fleetLaunchYaml({}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace meshnav::transport
