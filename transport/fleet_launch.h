#pragma once
/// @file fleet_launch.h
/// @brief A fleet over LCM (docs/fleet.md, "A fleet over LCM"): the launch file
/// (config/launch/README.md, run by scripts/supervisor.py) that starts, per vehicle of a fleet
/// file, its imu_bridge and uwb_bridge replaying its dataset and its estimator, each with
/// `--channel-prefix NAME` (the vehicle's name: `v0/IMU`, `v0/POSE`; transport/channels.h), and
/// optionally a logger per vehicle. Generated, not written by hand, so that a fleet file of any
/// size becomes one launch of the existing supervisor (`./meshnav up --fleet FILE`,
/// `meshnav_fleet_launch`). Optionally a calibrator (and a mission) for one vehicle or for the
/// whole fleet.
///
/// Buses (transport/fleet_bus.h): by default each vehicle's processes get `--lcm-url` of the
/// vehicle's own bus (the base URL's port + 1 + its index in the fleet file), so that a vehicle's
/// processes receive only its own traffic; `FleetBus::kShared` puts every process on the base URL
/// (no `--lcm-url` unless `lcm_url` is given: the launch environment's LCM_DEFAULT_URL). A
/// `calibrator_for` vehicle's calibrator and mission sit on that vehicle's bus, with its CALIB_CMD,
/// CALIB_STATUS and MISSION_STATUS (docs/decisions/017-bus-per-vehicle.md).
///
/// Process names are `<vehicle>_estimator`, `<vehicle>_imu_bridge`, `<vehicle>_uwb_bridge`,
/// `<vehicle>_logging` (and `<vehicle>_calibrator`, `<vehicle>_mission` for `calibrator_for`;
/// `fleet_calibrator`, `fleet_mission`, `fleet_peer_router` for the fleet); the launch stops when every bridge has played its data
/// (`shutdown_after`), the loggers last (`stop_last`). Variables of the generated file: BIN
/// (default build/bin), RATE (default 1), DATA_T0 (default 0), ESTIMATOR_CONFIG (default the
/// generator's `estimator_config`), OUT (only with `logging`: OUT/<vehicle>/ gets the logger's files
/// and the estimator's checkpoint).

#include <string>
#include <vector>

#include "common/fleet_file.h"
#include "transport/fleet_bus.h"

namespace meshnav::transport {

/// What the generated launch runs besides the bridges and estimators.
struct FleetLaunchOptions {
  /// Estimator options of every vehicle (`--config`; ESTIMATOR_CONFIG overrides it at launch).
  /// config/fleet_scale.yaml: what 100 anchors need (docs/fleet.md, "The estimator's cost").
  std::string estimator_config = "config/fleet_scale.yaml";
  bool logging = true;          ///< a logger per vehicle (`--channel-prefix`, writing ${OUT}/<vehicle>)
  double wait_timeout_s = 60.0;  ///< bridges give up when their estimator's ESTIMATOR_STATUS is not heard [s]
  /// Wall time [s] between the last bridge's end and the stop of the others: what an estimator
  /// still has queued is fused and published meanwhile (the bench waits longer than a run).
  double shutdown_delay_s = 2.0;
  std::string source;            ///< the fleet file's path, named in the header comment
  /// Non-empty: a calibrator and (with `mission`) a mission serving this one vehicle over LCM
  /// (`--channel-prefix` it: its RANGE, POSE, ANCHORS in, its ANCHOR_INIT out; the unprefixed
  /// CALIB_CMD, CALIB_STATUS and MISSION_STATUS go on that vehicle's bus), so that it gets its
  /// fly-by anchors only (for the whole fleet: `fleet_calibrator`).
  std::string calibrator_for;
  /// One calibrator serving every vehicle (`calibrator --fleet source --bus ...`, process
  /// `fleet_calibrator`): each vehicle's RANGE, POSE, ANCHORS in and its own ANCHOR_INIT out on its
  /// bus; CALIB_CMD and CALIB_STATUS on the first vehicle's bus, where the fleet's mission
  /// (`fleet_mission`, with `mission`: `mission --fleet`) follows that vehicle and from where it
  /// sends ESTIMATOR_CMD to every vehicle on its bus. Excludes calibrator_for; needs `source`.
  bool fleet_calibrator = false;
  /// With `source` and two or more vehicles: the fleet's `peer_router` (process `fleet_peer_router`,
  /// `peer_router --fleet source --bus ...`): every vehicle's RANGE, POSE and ANCHOR_INIT in, each
  /// inter-vehicle range out as PEER_RANGE to the vehicle that fuses it, as in one process
  /// (docs/fleet.md "Inter-vehicle ranges over LCM"). False: every estimator drops them.
  bool peer_router = true;
  std::string mission;  ///< mission file of calibrator_for's or the fleet calibrator's mission ("" none)
  std::string calibrator_config = "config/calibrator.yaml";  ///< the calibrator's options
  /// A bus per vehicle (each process of vehicle k: `--lcm-url` vehicleLcmUrl(bus, lcm_url, k)) or
  /// one shared bus (`--lcm-url` only when lcm_url is given).
  FleetBus bus = FleetBus::kPerVehicle;
  /// The base URL of the buses ("" = resolveLcmUrl(""): LCM_DEFAULT_URL, else LCM's default);
  /// must be udpm:// for kPerVehicle.
  std::string lcm_url;
};

/// The launch file (YAML text) of `vehicles`. Throws std::invalid_argument for a vehicle name that
/// is no channel prefix (channels::prefixProblem; loadFleetFile already refuses those) and for a
/// `calibrator_for` that names no vehicle or comes with `fleet_calibrator`, for `fleet_calibrator`
/// without `source`, and (vehicleLcmUrl) for kPerVehicle with a base URL that
/// is not udpm or whose ports run past 65535.
std::string fleetLaunchYaml(const std::vector<FleetEntry>& vehicles, const FleetLaunchOptions& options);

}  // namespace meshnav::transport
