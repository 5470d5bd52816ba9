/// @file meshnav_sim_main.cpp
/// @brief `meshnav_sim --seed N --out DIR ...`: writes one simulated sequence of the paper's
/// scenario as a dataset folder (DESIGN §6, §7).

#include <spdlog/spdlog.h>

#include <exception>
#include <iostream>

#include "common/cli.h"
#include "common/dataset.h"
#include "sim/paper_scenario.h"
#include "sim/scenario_simulator.h"
#include "sim/uncertain_anchors.h"

namespace {
constexpr const char* kUsage = R"(meshnav_sim: simulate one sequence of the paper's scenario (DESIGN §7)

Usage: meshnav_sim --seed N --out DIR [options]

  --seed N                 sequence seed; 1-12 are the twelve sequences (default 1)
  --out DIR                output dataset folder (required; created if needed)
  --sigma-range M          UWB range noise sigma_d [m] (default 0.1)
  --outlier-fraction F     fraction of NLOS outlier ranges, +U(0.5, 3) m (default 0.05)
  --drop-fraction F        fraction of dropped range messages (default 0.02)
  --duration-scale S       multiply every time constant of the flight (default 1: ~140 s)
  --no-initial-pose        do not write the take-off pad prior to setup.yaml
  --uncertain-anchors M    write the anchors that are not known (106-110) to setup.yaml as
                           truth + N(0, M^2) per axis (seeded by --seed) with position sigma M [m],
                           so that the estimator refines them online, with a-priori pair biases for
                           every pair (as for 101-104); 101-104 stay exact; truth.yaml is unchanged
                           (default: off, only 101-104 in setup.yaml)
  --uncertain-known-anchors
                           with --uncertain-anchors: perturb 101-104 as well (no exact anchor left:
                           the frame is held by the priors only)
  --help                   this text

Writes imu.csv (200 Hz), baro.csv (50 Hz), ranges.csv (meshed TDMA, 11 devices, 10 ms slots),
flight_state.csv (10 Hz), groundtruth.csv (60 Hz, TUM), setup.yaml (what a user knows) and
truth.yaml (evaluation only). The same seed and options give the same files.
)";
}  // namespace

int main(int argc, char** argv) {
  meshnav::setupLogging("meshnav_sim");
  meshnav::Cli cli("meshnav_sim", kUsage);
  cli.option("seed").option("out").option("sigma-range").option("outlier-fraction").option("drop-fraction")
      .option("duration-scale").option("no-initial-pose", false).option("uncertain-anchors")
      .option("uncertain-known-anchors", false);
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
  try {
    meshnav::sim::SimulationOptions options;
    const int64_t seed = cli.getInt("seed", 1);
    if (seed < 0) throw std::invalid_argument("--seed must be >= 0");
    options.seed = static_cast<uint64_t>(seed);
    options.uwb.sigma_range_m = cli.getDouble("sigma-range", options.uwb.sigma_range_m);
    options.uwb.outlier_fraction = cli.getDouble("outlier-fraction", options.uwb.outlier_fraction);
    options.uwb.drop_fraction = cli.getDouble("drop-fraction", options.uwb.drop_fraction);
    options.duration_scale = cli.getDouble("duration-scale", options.duration_scale);
    options.with_initial_pose = !cli.has("no-initial-pose");
    options.validate();
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
                   uncertain_sigma_m, uo.include_known ? "all" : "101-104 exact", result.dataset.setup.pair_biases.size());
    }
    spdlog::info("{}", result.trajectory.toString());
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
