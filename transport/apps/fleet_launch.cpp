/// meshnav_fleet_launch: a fleet file -> the launch file that runs the fleet over LCM, each vehicle
/// on its own prefixed channels (transport/fleet_launch.h; `./meshnav up --fleet FILE` runs it).
#include <filesystem>
#include <fstream>
#include <iostream>

#include <spdlog/spdlog.h>

#include "common/cli.h"
#include "common/fleet_file.h"
#include "transport/fleet_launch.h"

int main(int argc, char** argv) {
  using namespace meshnav;
  namespace fs = std::filesystem;
  Cli cli("meshnav_fleet_launch",
          "Writes the launch file (scripts/supervisor.py) of a fleet over LCM: per vehicle of --fleet its estimator, "
          "imu_bridge and uwb_bridge (and a logger unless --no-logging), each with --channel-prefix <vehicle name> "
          "and, with --bus per-vehicle (the default), on the vehicle's own LCM bus; run it with ./meshnav up FILE OUT=DIR [RATE=X] (docs/fleet.md, \"A fleet over LCM\").");
  std::string fleet, out, bus = "per-vehicle";
  bool no_logging = false;
  transport::FleetLaunchOptions o;
  cli.optional("fleet", fleet, "fleet file (docs/fleet.md), e.g. DIR/fleet.yaml of meshnav_sim --vehicles N")
      ->type_name("FILE")
      ->required();
  cli.optional("out", out, "the launch file to write")->type_name("FILE")->required();
  cli.option("estimator-config", o.estimator_config,
             "estimator options of every vehicle (the launch's ESTIMATOR_CONFIG overrides it); made absolute when it "
             "exists")
      ->type_name("FILE");
  cli.flag("no-logging", no_logging, "no logger per vehicle (the launch then needs no OUT)");
  cli.option("wait-timeout", o.wait_timeout_s, "bridges give up when their estimator is not heard within S seconds")
      ->type_name("S")
      ->check(cli::positive());
  cli.option("shutdown-delay", o.shutdown_delay_s,
             "wall seconds from the end of the last bridge's data to the stop of the others (an estimator fuses what "
             "it still has queued meanwhile)")
      ->type_name("S")
      ->check(cli::nonNegative());
  CLI::Option* for_one = cli.optional("calibrator-for", o.calibrator_for,
                                      "a calibrator serving this vehicle alone over LCM (its fly-by anchors only)")
                             ->type_name("NAME");
  CLI::Option* for_all =
      cli.flag("fleet-calibrator", o.fleet_calibrator,
               "one calibrator serving every vehicle over LCM (calibrator --fleet): each vehicle's fly-by anchors from "
               "every vehicle's ranges, each vehicle's ANCHOR_INIT on its own bus; CALIB_CMD, CALIB_STATUS and the "
               "mission on the first vehicle's bus");
  for_all->excludes(for_one);
  bool no_peer_router = false;
  cli.flag("no-peer-router", no_peer_router,
           "no peer_router: every estimator drops the ranges to other vehicles' tags (by default the fleet's "
           "peer_router sends each to the vehicle that fuses it, as meshnav_run --fleet does)");
  cli.optional("mission", o.mission,
               "with --calibrator-for or --fleet-calibrator: the mission file (e.g. the fleet's mission.yaml; the "
               "fleet's mission hears the first vehicle)")
      ->type_name("FILE");
  cli.option("calibrator-config", o.calibrator_config,
             "with --calibrator-for or --fleet-calibrator: the calibrator's options; made absolute when it exists")
      ->type_name("FILE");
  cli.option("bus", bus,
             "per-vehicle: vehicle k (its index in --fleet, from 0) on the --lcm-url's port + 1 + k, so that its "
             "processes receive only its own traffic; shared: every vehicle on --lcm-url (docs/fleet.md)")
      ->type_name("POLICY")
      ->check(CLI::IsMember({"per-vehicle", "shared"}));
  cli.optional("lcm-url", o.lcm_url,
               "the base LCM URL of the buses (udpm:// for --bus per-vehicle; default: $LCM_DEFAULT_URL, else "
               "udpm://239.255.76.67:7667?ttl=0)")
      ->type_name("URL");
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  setupLogging("meshnav_fleet_launch");
  if (!o.mission.empty() && o.calibrator_for.empty() && !o.fleet_calibrator) {
    spdlog::error("--mission needs --calibrator-for or --fleet-calibrator (a mission drives a calibrator)");
    return 2;
  }
  try {
    std::vector<FleetEntry> vehicles = loadFleetFile(fleet);
    for (FleetEntry& v : vehicles) v.dataset = fs::absolute(v.dataset).lexically_normal().string();
    if (fs::exists(o.estimator_config)) o.estimator_config = fs::absolute(o.estimator_config).lexically_normal().string();
    o.logging = !no_logging;
    o.peer_router = !no_peer_router;
    o.bus = transport::parseFleetBus(bus);
    if (fs::exists(o.calibrator_config)) o.calibrator_config = fs::absolute(o.calibrator_config).lexically_normal().string();
    if (!o.mission.empty()) o.mission = fs::absolute(o.mission).lexically_normal().string();
    o.source = fs::absolute(fleet).lexically_normal().string();
    const std::string text = transport::fleetLaunchYaml(vehicles, o);
    std::ofstream f(out);
    f << text;
    f.close();
    if (!f) throw std::runtime_error("cannot write " + out);
    spdlog::info("{}: {} vehicles, {} bus{}", out, vehicles.size(), bus,
                 o.fleet_calibrator         ? std::string(", a calibrator for the fleet")
                 : o.calibrator_for.empty() ? std::string()
                                            : ", a calibrator for " + o.calibrator_for);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  return 0;
}
