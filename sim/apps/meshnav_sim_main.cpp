/// @file meshnav_sim_main.cpp
/// @brief `meshnav_sim --seed N --out DIR ...`: writes one simulated sequence as a dataset folder
/// (DESIGN §6): the paper's scenario (DESIGN §7) by default, or a generated scenario
/// (docs/scenarios.md: trajectory kind, hall, anchor layout, tags, noise, IMU grade, duration).

#include <spdlog/spdlog.h>

#include <exception>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "common/cli.h"
#include "common/dataset.h"
#include "sim/scenario_simulator.h"
#include "sim/uncertain_anchors.h"

namespace {
constexpr const char* kUsage = R"(meshnav_sim: simulate one sequence (the paper's scenario by default, DESIGN §7)

Usage: meshnav_sim --seed N --out DIR [options]

  --seed N                 sequence seed; 1-12 are the twelve sequences (default 1); every random
                           choice below (flight, anchors, noise) is drawn from it
  --out DIR                output dataset folder (required; created if needed)

Scenario (defaults: the paper's scenario):
  --trajectory KIND        spiral|figure8|lawnmower|helix|hover|walk (default spiral: the paper's
                           flight). hover starts in the air; walk is a hand-held rig at 0.9-1.5 m
                           with no take-off, no landed state and no barometer
  --hall X,Y,Z             hall size [m], centred on x = y = 0, floor at z = 0; X, Y in [3, 100],
                           Z in [2.5, 30] (default: the paper's hall, 5.5 x 8.4 x 8.2 m)
  --anchor-layout L        paper|walls|one-wall|ceiling|random (default paper: the paper's anchors,
                           mapped into --hall)
  --tags N                 UWB tags on the vehicle, 1-3: 100, 105, 99 (default 2)
  --known N                anchors with known positions in setup.yaml, 3-5 (default 4: 101-104)
  --unknown N              further anchors, only in truth.yaml (fly-by calibration), 0-20
                           (default 5: 106-110; paper layout: --known + --unknown <= 9)
  --duration S             sequence length [s], 30-3600 (default 140 s x --duration-scale; for
                           spiral the paper's flight is time-scaled to about S)
  --duration-scale S       multiply every time constant of the flight (default 1: ~140 s)

Sensors:
  --sigma-range M          UWB range noise sigma_d [m] (default 0.1)
  --outliers F             fraction of NLOS outlier ranges, +U(0.5, 3) m (default 0.05);
  --outlier-fraction F     the same
  --drop F                 fraction of dropped range messages (default 0.02);
  --drop-fraction F        the same
  --bias-max M             max |constant pairwise bias gamma| of the UWB hardware [m], (0, 2]
                           (default 0.4; gamma ~ N(0, (0.375 M)^2) clipped to +-M)
  --imu-grade G            consumer|fc|tactical IMU noise densities and bias random walks, written
                           to setup.yaml noise: (default fc, a flight-controller IMU)
  --no-initial-pose        do not write the take-off pad prior to setup.yaml (never written for
                           hover and walk, which do not start on a pad)
  --uncertain-anchors M    write the anchors that are not known (106-110) to setup.yaml as
                           truth + N(0, M^2) per axis (seeded by --seed) with position sigma M [m],
                           so that the estimator refines them online, with a-priori pair biases for
                           every pair (as for 101-104); 101-104 stay exact; truth.yaml is unchanged
                           (default: off, only 101-104 in setup.yaml)
  --uncertain-known-anchors
                           with --uncertain-anchors: perturb 101-104 as well (no exact anchor left:
                           the frame is held by the priors only)
  --help                   this text

Writes imu.csv (200 Hz), baro.csv (50 Hz; not for walk), ranges.csv (meshed TDMA over every tag
and anchor, 10 ms slots), flight_state.csv (10 Hz; only for motions with a landed phase),
groundtruth.csv (60 Hz, TUM), setup.yaml (what a user knows) and truth.yaml (evaluation only).
The same seed and options give the same files.
)";

/// "X,Y,Z" → three numbers; throws naming --hall.
Eigen::Vector3d parseHall(const std::string& text) {
  std::istringstream in(text);
  Eigen::Vector3d v;
  char sep1 = 0, sep2 = 0;
  if (!(in >> v.x() >> sep1 >> v.y() >> sep2 >> v.z()) || sep1 != ',' || sep2 != ',' || !(in >> std::ws).eof())
    throw std::invalid_argument("--hall expects X,Y,Z in metres (e.g. 10,8,4), got '" + text + "'");
  return v;
}

int intOption(const meshnav::Cli& cli, const char* name, int fallback, int lo, int hi) {
  const int64_t v = cli.getInt(name, fallback);
  if (v < lo || v > hi)
    throw std::invalid_argument("--" + std::string(name) + " must be in [" + std::to_string(lo) + ", " +
                                std::to_string(hi) + "], got " + std::to_string(v));
  return static_cast<int>(v);
}

/// The scenario-generator options (see kUsage).
void applyScenarioOptions(const meshnav::Cli& cli, meshnav::sim::SimulationOptions& o) {
  using namespace meshnav::sim;
  if (cli.has("trajectory")) {
    const auto kind = parseTrajectoryKind(cli.get("trajectory"));
    if (!kind) throw std::invalid_argument("--trajectory must be one of " + trajectoryKindNames() + ", got '" + cli.get("trajectory") + "'");
    o.trajectory_kind = *kind;
  }
  if (cli.has("anchor-layout")) {
    const auto layout = parseAnchorLayoutKind(cli.get("anchor-layout"));
    if (!layout) throw std::invalid_argument("--anchor-layout must be one of " + anchorLayoutKindNames() + ", got '" + cli.get("anchor-layout") + "'");
    o.anchor_layout = *layout;
  }
  if (cli.has("hall")) o.hall_size_m = parseHall(cli.get("hall"));
  o.n_tags = intOption(cli, "tags", o.n_tags, 1, 3);
  o.n_known_anchors = intOption(cli, "known", o.n_known_anchors, 3, 5);
  o.n_unknown_anchors = intOption(cli, "unknown", o.n_unknown_anchors, 0, 20);
  if (cli.has("duration")) o.duration_s = cli.getDouble("duration", 140.0);
  if (cli.has("imu-grade")) {
    try {
      o.imu = ImuNoiseOptions::forGrade(cli.get("imu-grade"));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("--imu-grade: ") + e.what());
    }
  }
  if (cli.has("bias-max")) {
    const double m = cli.getDouble("bias-max", o.hardware.gamma_max_m);
    if (!(m > 0.0 && m <= 2.0)) throw std::invalid_argument("--bias-max must be in (0, 2] m");
    o.hardware.gamma_sigma_m = 0.375 * m;  // the default 0.15 m for 0.4 m
    o.hardware.gamma_max_m = m;
  }
}

meshnav::sim::SimulationOptions optionsFrom(const meshnav::Cli& cli) {
  meshnav::sim::SimulationOptions options;
  const int64_t seed = cli.getInt("seed", 1);
  if (seed < 0) throw std::invalid_argument("--seed must be >= 0");
  options.seed = static_cast<uint64_t>(seed);
  options.uwb.sigma_range_m = cli.getDouble("sigma-range", options.uwb.sigma_range_m);
  if (cli.has("outliers") && cli.has("outlier-fraction")) throw std::invalid_argument("give --outliers or --outlier-fraction, not both");
  if (cli.has("drop") && cli.has("drop-fraction")) throw std::invalid_argument("give --drop or --drop-fraction, not both");
  options.uwb.outlier_fraction = cli.getDouble(cli.has("outliers") ? "outliers" : "outlier-fraction", options.uwb.outlier_fraction);
  options.uwb.drop_fraction = cli.getDouble(cli.has("drop") ? "drop" : "drop-fraction", options.uwb.drop_fraction);
  options.duration_scale = cli.getDouble("duration-scale", options.duration_scale);
  options.with_initial_pose = !cli.has("no-initial-pose");
  applyScenarioOptions(cli, options);
  options.validate();
  return options;
}
}  // namespace

int main(int argc, char** argv) {
  meshnav::setupLogging("meshnav_sim");
  meshnav::Cli cli("meshnav_sim", kUsage);
  cli.option("seed").option("out").option("sigma-range").option("outlier-fraction").option("drop-fraction")
      .option("outliers").option("drop").option("duration-scale").option("no-initial-pose", false)
      .option("uncertain-anchors").option("uncertain-known-anchors", false).option("trajectory").option("hall")
      .option("anchor-layout").option("tags").option("known").option("unknown").option("bias-max")
      .option("imu-grade").option("duration");
  int exit_code = 0;
  if (!cli.parse(argc, argv, exit_code)) return exit_code;
  if (!cli.positional().empty()) {
    std::cerr << "meshnav_sim: unexpected argument '" << cli.positional().front() << "'\n\n" << kUsage;
    return 2;
  }
  if (!cli.has("out")) {
    std::cerr << "meshnav_sim: --out DIR is required\n\n" << kUsage;
    return 2;
  }
  meshnav::sim::SimulationOptions options;
  try {
    options = optionsFrom(cli);
  } catch (const std::exception& e) {
    std::cerr << "meshnav_sim: " << e.what() << "\n(see meshnav_sim --help)\n";
    return 2;
  }
  try {
    spdlog::info("simulating: {}", options.toString());
    const double uncertain_sigma_m = cli.getDouble("uncertain-anchors", 0.0);
    if (cli.has("uncertain-anchors") && !(uncertain_sigma_m > 0.0 && uncertain_sigma_m < 10.0))
      throw std::invalid_argument("--uncertain-anchors must be in (0, 10) m");
    if (cli.has("uncertain-known-anchors") && !cli.has("uncertain-anchors"))
      throw std::invalid_argument("--uncertain-known-anchors needs --uncertain-anchors M");

    const meshnav::sim::ScenarioSimulator simulator(options);
    meshnav::sim::SimulationResult result = simulator.run();
    if (cli.has("uncertain-anchors")) {
      meshnav::sim::UncertainAnchorOptions uo;
      uo.sigma_m = uncertain_sigma_m;
      uo.include_known = cli.has("uncertain-known-anchors");
      uo.seed = options.seed;
      const int n = meshnav::sim::makeAnchorsUncertain(result.dataset, uo, options.hardware, options.uwb.sigma_range_m);
      spdlog::info("uncertain anchors: {} anchors written with sigma {} m ({}), {} a-priori pair biases", n,
                   uncertain_sigma_m, uo.include_known ? "all" : "known anchors exact", result.dataset.setup.pair_biases.size());
    }
    spdlog::info("{}", result.trajectory_description);
    const std::string out = cli.get("out");
    spdlog::info("writing dataset to {}", out);
    meshnav::writeDataset(result.dataset, out);
    std::cout << result.summary() << "\nDataset written to " << out << std::endl;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  return 0;
}
