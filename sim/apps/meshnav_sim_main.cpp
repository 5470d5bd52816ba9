/// @file meshnav_sim_main.cpp
/// @brief `meshnav_sim --seed N --out DIR ...`: writes one simulated sequence as a dataset folder
/// (docs/formats.md): the paper's scenario by default, or a generated scenario
/// (docs/scenarios.md: trajectory kind, hall, anchor layout, tags, noise, IMU grade, duration).

#include <spdlog/spdlog.h>

#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "common/atomic_file.h"
#include "common/cli_main.h"
#include "common/dataset.h"
#include "sim/fleet_simulation.h"
#include "sim/scaled_fleet_simulation.h"
#include "sim/scenario_simulator.h"
#include "sim/uncertain_anchors.h"

namespace {

constexpr char kDescription[] =
    "Simulates one sequence (the paper's scenario by default; docs/scenarios.md) and writes it as a dataset folder: "
    "imu.csv (200 Hz), baro.csv (50 Hz; not for walk), ranges.csv (meshed TDMA over every tag and anchor, 10 ms "
    "slots), flight_state.csv (10 Hz; only for motions with a landed phase), groundtruth.csv (60 Hz, TUM), "
    "setup.yaml (what a user knows) and truth.yaml (evaluation only). The same seed and options give the same files.";
/// The command line: the simulation options (their defaults are the code's) and the texts that
/// are parsed after the command line.
struct SimCli {
  meshnav::sim::SimulationOptions sim;
  int64_t seed = 1;
  std::string out, trajectory, hall, anchor_layout, imu_grade, nlos = "uniform";
  double duration_s = 0.0;
  double bias_max_m = 0.0;
  double uncertain_sigma_m = 0.0;
  double imu_scale_sigma = 0.0, imu_misalignment_deg = 0.0, vibration = 1.0;
  int fleet = 0;
  double inter_vehicle_hz = 0.0;
  meshnav::sim::ScaledFleetOptions scaled;  ///< --vehicles: its base options are `sim`
  std::string outage;
  bool no_initial_pose = false, uncertain_known = false;
};

void declareOptions(meshnav::Cli& cli, SimCli& c) {
  namespace cli_checks = meshnav::cli;
  auto& o = c.sim;
  cli.option("seed", c.seed,
             "sequence seed; 1-12 are the twelve sequences; every random choice below (flight, anchors, noise) is "
             "drawn from it")
      ->type_name("N")
      ->check(CLI::NonNegativeNumber);
  cli.optional("out", c.out, "output dataset folder (created if needed)")->type_name("DIR")->required();
  cli.optional("fleet", c.fleet,
               "simulate N vehicles (1-16) in one hall among the same anchors: vehicle k with seed --seed + k, tag "
               "ids + 1000 k, the anchors' mesh ranges of vehicle 0; writes the datasets --out/v0 ... and "
               "--out/fleet.yaml for 'meshnav run --fleet' (docs/fleet.md)")
      ->type_name("N")
      ->check(CLI::Range(1, 16));
  cli.option("inter-vehicle-hz", c.inter_vehicle_hz,
             "with --fleet: every pair of vehicles also ranges tag to tag at this rate, one tag pair per exchange, "
             "into the first vehicle's ranges.csv (type T at both ends; docs/fleet.md); 0 = none [Hz]")
      ->type_name("F")
      ->check(CLI::Range(0.0, 100.0))
      ->needs("--fleet");
  auto* vehicles =
      cli.optional("vehicles", c.scaled.n_vehicles,
                   "a fleet of N vehicles (1-16) among --anchors anchors in TDMA cells in a large hall (--hall, default "
                   "40,40,10): anchors on a grid (walls, pillars, ceiling), 2 x 2 grid points per cell, cells reusing "
                   "slots 3 cells apart; vehicle k flies its own flight (spiral, figure8, lawnmower, helix in turn) in "
                   "its part of the hall with seed --seed + k and tags 100/105 + 1000 k; writes --out/v0 ..., "
                   "--out/fleet.yaml, --out/mission.yaml (calibrates the fly-by anchors) and --out/anchors_layout.csv "
                   "(docs/scenarios.md, 'A hundred anchors in TDMA cells')")
          ->type_name("N")
          ->check(CLI::Range(1, 16))
          ->group("Scaled fleet (--vehicles)");
  cli.option("anchors", c.scaled.n_anchors, "with --vehicles: anchors on the hall's grid, 4-400")
      ->type_name("M")->check(CLI::Range(4, 400))->needs(vehicles)->group("Scaled fleet (--vehicles)");
  cli.optional("fly-by", c.scaled.n_fly_by,
               "with --vehicles: anchors left out of setup.yaml (seeded choice), calibrated in flight by the "
               "generated mission (default 20 % of --anchors)")
      ->type_name("K")->check(CLI::NonNegativeNumber)->needs(vehicles)->group("Scaled fleet (--vehicles)");
  cli.optional("outage", c.outage,
               "with --vehicles: the anchors do not answer vehicle V's tags from T0 to T1 s (its tag-to-tag ranges "
               "go on): a vehicle without anchors among its neighbours")
      ->type_name("V,T0,T1")->needs(vehicles)->group("Scaled fleet (--vehicles)");
  cli.option("tdma-slot", c.scaled.tdma.slot_s,
             "with --vehicles: the cell TDMA's slot, one SDS-TWR exchange with guard time [s]")
      ->type_name("S")->check(cli_checks::positive())->needs(vehicles)->group("Scaled fleet (--vehicles)");
  cli.option("tdma-peer-slots", c.scaled.tdma.peer_slots,
             "with --vehicles: slots per fleet tag in each frame's peer phase, tag to tag across the hall (0: no peer "
             "phase, tags range to other vehicles' tags only within the cells' round robin; docs/scenarios.md)")
      ->type_name("K")->check(CLI::Range(0, 16))->needs(vehicles)->group("Scaled fleet (--vehicles)");
  cli.optional("trajectory", c.trajectory,
               "spiral|figure8|lawnmower|helix|hover|walk (default spiral: the paper's flight). hover starts in the "
               "air; walk is a hand-held rig at 0.9-1.5 m with no take-off, no landed state and no barometer "
               "(setup.yaml states its carried height, 1.2 +- 0.3 m)")
      ->type_name("KIND")
      ->group("Scenario (default: the paper's)");
  cli.optional("hall", c.hall,
               "hall size [m], centred on x = y = 0, floor at z = 0; X, Y in [3, 100], Z in [2.5, 30] (default: the "
               "paper's hall, 5.5 x 8.4 x 8.2 m)")
      ->type_name("X,Y,Z")
      ->group("Scenario (default: the paper's)");
  cli.optional("anchor-layout", c.anchor_layout,
               "paper|walls|one-wall|ceiling|random (default paper: the paper's anchors, mapped into --hall)")
      ->type_name("L")
      ->group("Scenario (default: the paper's)");
  cli.option("tags", o.n_tags, "UWB tags on the vehicle: 100, 105, 99")
      ->type_name("N")->check(CLI::Range(1, 3))->group("Scenario (default: the paper's)");
  cli.option("known", o.n_known_anchors, "anchors with known positions in setup.yaml (101-...)")
      ->type_name("N")->check(CLI::Range(3, 5))->group("Scenario (default: the paper's)");
  cli.option("unknown", o.n_unknown_anchors,
             "further anchors, only in truth.yaml (fly-by calibration; paper layout: --known + --unknown <= 9)")
      ->type_name("N")->check(CLI::Range(0, 20))->group("Scenario (default: the paper's)");
  cli.optional("duration", c.duration_s,
               "sequence length [s], 30-3600 (default 140 s x --duration-scale; for spiral the paper's flight is "
               "time-scaled to about S)")
      ->type_name("S")->check(cli_checks::finite())->group("Scenario (default: the paper's)");
  cli.option("duration-scale", o.duration_scale, "multiply every time constant of the flight")
      ->type_name("S")->check(cli_checks::positive())->group("Scenario (default: the paper's)");
  cli.option("sigma-range", o.uwb.sigma_range_m, "UWB range noise sigma_d [m]")
      ->type_name("M")->check(cli_checks::nonNegative())->group("Sensors");
  cli.option("outliers,--outlier-fraction", o.uwb.outlier_fraction, "fraction of NLOS outlier ranges (their excess: --nlos)")
      ->type_name("F")->check(cli_checks::nonNegative())->group("Sensors");
  cli.optional("nlos", c.nlos,
               "NLOS excess of an outlier: uniform = U(0.5, 3) m (the paper's, which a chi^2 gate removes), "
               "exponential = 0.2 m + Exp(mean 0.3 m) (real hardware's: most of it passes a gate)")
      ->type_name("uniform|exponential")->check(cli_checks::oneOf([](const std::string& v) {
        return v == "uniform" || v == "exponential"; }, "uniform|exponential"))->group("Sensors");
  cli.option("range-correlation", o.uwb.correlation_time_s,
             "correlation time of a pair's range error, a first-order process (real multipath: about 0.1 s at a "
             "walk), written to setup.yaml noise.range_correlation_time; 0 = independent [s]")
      ->type_name("S")->check(cli_checks::nonNegative())->group("Sensors");
  cli.option("range-time-offset", o.uwb.time_offset_s,
             "the UWB stamps' delay against the IMU clock: the distance at t is stamped t + S (issue 34 measured "
             "STAR-loc's IMU stamps leading its ranges by about 0.03 s); written to truth.yaml range_time_offset_s; "
             "setup.yaml then leaves it to the estimator (uwb_clock: its prior), while 0 writes uwb_clock.sigma_s: 0 "
             "(the clocks are one) [s]")
      ->type_name("S")->check(cli_checks::finite())->group("Sensors");
  cli.option("drop,--drop-fraction", o.uwb.drop_fraction, "fraction of dropped range messages")
      ->type_name("F")->check(cli_checks::nonNegative())->group("Sensors");
  cli.option("hardware-seed", o.hardware.hardware_seed,
             "seed of the UWB modules' pair biases and of their a-priori calibration's error, drawn once (the "
             "default is the paper scenario's fixed set: the same modules in every sequence; another seed is "
             "another set of modules, for consistency figures over hardware draws, docs/smoother.md)")
      ->type_name("N")->check(CLI::NonNegativeNumber)->group("Sensors");
  c.bias_max_m = o.hardware.gamma_max_m;
  cli.option("bias-max", c.bias_max_m,
             "max |constant pairwise bias gamma| of the UWB hardware [m], (0, 2]; gamma ~ N(0, (0.375 M)^2) clipped "
             "to +-M")
      ->type_name("M")->group("Sensors");
  cli.optional("imu-grade", c.imu_grade,
               "consumer|fc|tactical IMU noise densities and bias random walks, written to setup.yaml noise: "
               "(default fc, a flight-controller IMU)")
      ->type_name("G")->group("Sensors");
  cli.option("imu-scale-sigma", c.imu_scale_sigma,
             "sigma of each IMU axis's scale-factor error, accelerometer and gyroscope, drawn once (consumer MEMS: "
             "about 0.01); in truth.yaml imu_*_axes_*, not in setup.yaml; 0 = exact [-]")
      ->type_name("F")->check(cli_checks::nonNegative())->group("Sensors");
  cli.option("imu-misalignment", c.imu_misalignment_deg,
             "sigma of each off-diagonal term of the IMU's axis matrices (axes not orthogonal to the body's), both "
             "sensors, drawn once (consumer MEMS: about 0.5 deg); 0 = exact [deg]")
      ->type_name("DEG")->check(cli_checks::nonNegative())->group("Sensors");
  cli.option("vibration", c.vibration,
             "scale of the rotor vibration of the IMU while a rotorcraft is airborne (1: per axis about 0.4 m/s^2 "
             "and 0.02 rad/s RMS at 110-170 Hz rotor tones; 0: none, the IMU of a still body in hover and cruise) "
             "[-]")
      ->type_name("F")->check(cli_checks::nonNegative())->group("Sensors");
  cli.flag("no-initial-pose", c.no_initial_pose,
           "do not write the take-off pad prior to setup.yaml (never written for hover and walk)")
      ->group("Sensors");
  cli.optional("uncertain-anchors", c.uncertain_sigma_m,
               "write the anchors that are not known (106-110) to setup.yaml as truth + N(0, M^2) per axis (seeded by "
               "--seed) with position sigma M [m], so that the estimator refines them online, with a-priori pair "
               "biases for every pair; 101-104 stay exact; truth.yaml is unchanged (default: off)")
      ->type_name("M")->group("Sensors");
  cli.flag("uncertain-known-anchors", c.uncertain_known,
           "with --uncertain-anchors: perturb 101-104 as well (the frame is held by the priors only)")
      ->group("Sensors");
}

/// "X,Y,Z" → three numbers; throws naming --hall.
Eigen::Vector3d parseHall(const std::string& text) {
  std::istringstream in(text);
  Eigen::Vector3d v;
  char sep1 = 0, sep2 = 0;
  if (!(in >> v.x() >> sep1 >> v.y() >> sep2 >> v.z()) || sep1 != ',' || sep2 != ',' || !(in >> std::ws).eof())
    throw std::invalid_argument("--hall expects X,Y,Z in metres (e.g. 10,8,4), got '" + text + "'");
  return v;
}

/// The options given as text (kinds, hall, IMU grade, bias bound), checked with messages naming them.
void applyScenarioOptions(const meshnav::Cli& cli, SimCli& c) {
  using namespace meshnav::sim;
  auto& o = c.sim;
  if (cli.given("trajectory")) {
    const auto kind = parseTrajectoryKind(c.trajectory);
    if (!kind) throw std::invalid_argument("--trajectory must be one of " + trajectoryKindNames() + ", got '" + c.trajectory + "'");
    o.trajectory_kind = *kind;
  }
  if (cli.given("anchor-layout")) {
    const auto layout = parseAnchorLayoutKind(c.anchor_layout);
    if (!layout) throw std::invalid_argument("--anchor-layout must be one of " + anchorLayoutKindNames() + ", got '" + c.anchor_layout + "'");
    o.anchor_layout = *layout;
  }
  if (cli.given("hall")) o.hall_size_m = parseHall(c.hall);
  if (c.nlos == "exponential") {
    o.uwb.nlos_excess = "exponential";
    o.uwb.outlier_min_m = 0.2;
    o.uwb.outlier_mean_m = 0.3;
  }
  if (cli.given("duration")) o.duration_s = c.duration_s;
  if (cli.given("imu-grade")) {
    try {
      o.imu = ImuNoiseOptions::forGrade(c.imu_grade);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("--imu-grade: ") + e.what());
    }
  }
  o.imu.scale_sigma = c.imu_scale_sigma;  // after the grade, which sets the noise figures only
  o.imu.misalignment_sigma_rad = c.imu_misalignment_deg * M_PI / 180.0;
  o.imu.vibration_acc_m_s2 *= c.vibration;  // scales the grade's (the default) amplitudes
  o.imu.vibration_gyro_rad_s *= c.vibration;
  if (cli.given("bias-max")) {
    if (!(c.bias_max_m > 0.0 && c.bias_max_m <= 2.0)) throw std::invalid_argument("--bias-max must be in (0, 2] m");
    o.hardware.gamma_sigma_m = 0.375 * c.bias_max_m;  // the default 0.15 m for 0.4 m
    o.hardware.gamma_max_m = c.bias_max_m;
  }
  if (cli.given("uncertain-anchors") && !(c.uncertain_sigma_m > 0.0 && c.uncertain_sigma_m < 10.0))
    throw std::invalid_argument("--uncertain-anchors must be in (0, 10) m");
  if (cli.given("fleet") && cli.given("uncertain-anchors"))
    throw std::invalid_argument("--uncertain-anchors is not supported with --fleet (its a-priori pair biases are drawn per vehicle)");
  if (cli.given("vehicles"))
    for (const char* other : {"fleet", "inter-vehicle-hz", "trajectory", "anchor-layout", "tags", "known", "unknown",
                              "uncertain-anchors", "range-correlation"})
      if (cli.given(other))
        throw std::invalid_argument(std::string("--") + other + " is not an option of a scaled fleet (--vehicles)");
  if (cli.given("outage")) {
    std::istringstream in(c.outage);
    char s1 = 0, s2 = 0;
    auto& out = c.scaled.outage;
    if (!(in >> out.vehicle >> s1 >> out.t0_s >> s2 >> out.t1_s) || s1 != ',' || s2 != ',' || !(in >> std::ws).eof() ||
        out.vehicle < 0)
      throw std::invalid_argument("--outage expects V,T0,T1 (vehicle index, seconds), got '" + c.outage + "'");
  }
  if (c.uncertain_known && !cli.given("uncertain-anchors"))
    throw std::invalid_argument("--uncertain-known-anchors needs --uncertain-anchors M");
  o.seed = static_cast<uint64_t>(c.seed);
  o.with_initial_pose = !c.no_initial_pose;
  o.validate();
}

/// --fleet N: the datasets out/v0 ... and out/fleet.yaml.
int simulateFleet(const meshnav::sim::SimulationOptions& options, int n, double inter_vehicle_hz, const std::string& out) {
  const auto fleet = meshnav::sim::simulateFleet(options, n, inter_vehicle_hz);
  std::filesystem::create_directories(out);
  std::string list;
  for (size_t k = 0; k < fleet.size(); ++k) {
    const std::string name = "v" + std::to_string(k);
    const std::string dir = (std::filesystem::path(out) / name).string();
    spdlog::info("vehicle {}: {}", name, fleet[k].trajectory_description);
    meshnav::writeDataset(fleet[k].dataset, dir);
    std::cout << name << ": " << fleet[k].summary() << "\n";
    list += "  - {name: " + name + ", dataset: " + name + "}\n";
  }
  meshnav::writeFileAtomically((std::filesystem::path(out) / "fleet.yaml").string(), [&](std::ostream& file) {
    file << "# a simulated fleet (meshnav_sim --fleet " << n << " --seed " << options.seed
         << "): one hall, one anchor map; docs/fleet.md\nvehicles:\n"
         << list;
  });
  std::cout << "Fleet of " << n << " written to " << out << " (fleet.yaml)" << std::endl;
  return 0;
}

/// --vehicles N: the datasets out/v0 ..., out/fleet.yaml, out/mission.yaml, out/anchors_layout.csv.
int simulateScaledFleet(meshnav::sim::ScaledFleetOptions options, const meshnav::sim::SimulationOptions& base,
                        const std::string& out) {
  options.base = base;
  try {
    options.validate();
  } catch (const std::exception& e) {
    std::cerr << "meshnav_sim: " << e.what() << "\n(see meshnav_sim --help)\n";
    return 2;
  }
  spdlog::info("{}", options.toString());
  const auto fleet = meshnav::sim::simulateScaledFleet(options);
  std::filesystem::create_directories(out);
  std::string list;
  for (size_t k = 0; k < fleet.vehicles.size(); ++k) {
    const std::string name = "v" + std::to_string(k);
    spdlog::info("writing vehicle {} ({}/{})", name, k + 1, fleet.vehicles.size());
    meshnav::writeDataset(fleet.vehicles[k].dataset, (std::filesystem::path(out) / name).string());
    list += "  - {name: " + name + ", dataset: " + name + "}\n";
  }
  const std::filesystem::path dir(out);
  meshnav::writeFileAtomically((dir / "fleet.yaml").string(), [&](std::ostream& file) {
    file << "# a simulated fleet (meshnav_sim --vehicles " << options.n_vehicles << " --anchors " << options.n_anchors
         << " --seed " << base.seed << "): one hall, one anchor map; docs/fleet.md\nvehicles:\n"
         << list;
  });
  meshnav::writeFileAtomically((dir / "mission.yaml").string(), [&](std::ostream& file) { file << fleet.mission_yaml; });
  meshnav::writeFileAtomically((dir / "anchors_layout.csv").string(), [&](std::ostream& file) { file << fleet.layout_csv; });
  std::cout << fleet.description << "Fleet of " << options.n_vehicles << " written to " << out
            << " (fleet.yaml, mission.yaml, anchors_layout.csv)" << std::endl;
  return 0;
}

/// The work of main: the scenario options checked (a bad combination: exit 2), then the sequence
/// simulated and written.
int simulate(const meshnav::Cli& cli, SimCli& c) {
  try {
    applyScenarioOptions(cli, c);
  } catch (const std::exception& e) {
    std::cerr << "meshnav_sim: " << e.what() << "\n(see meshnav_sim --help)\n";
    return 2;
  }
  const auto& options = c.sim;
  if (cli.given("vehicles")) return simulateScaledFleet(c.scaled, options, c.out);
  spdlog::info("simulating: {}", options.toString());
  if (cli.given("fleet")) return simulateFleet(options, c.fleet, c.inter_vehicle_hz, c.out);
  const meshnav::sim::ScenarioSimulator simulator(options);
  meshnav::sim::SimulationResult result = simulator.run();
  if (cli.given("uncertain-anchors")) {
    meshnav::sim::UncertainAnchorOptions uo;
    uo.sigma_m = c.uncertain_sigma_m;
    uo.include_known = c.uncertain_known;
    uo.seed = options.seed;
    const int n = meshnav::sim::makeAnchorsUncertain(result.dataset, uo, options.hardware, options.uwb.sigma_range_m);
    spdlog::info("uncertain anchors: {} anchors written with sigma {} m ({}), {} a-priori pair biases", n,
                 c.uncertain_sigma_m, uo.include_known ? "all" : "known anchors exact", result.dataset.setup.pair_biases.size());
  }
  spdlog::info("{}", result.trajectory_description);
  spdlog::info("writing dataset to {}", c.out);
  meshnav::writeDataset(result.dataset, c.out);
  std::cout << result.summary() << "\nDataset written to " << c.out << std::endl;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return meshnav::cliMain<SimCli>(argc, argv, "meshnav_sim", kDescription, declareOptions, simulate);
}
