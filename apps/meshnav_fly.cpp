/// @file meshnav_fly.cpp
/// @brief `meshnav fly`: a closed-loop flight in one process, lock-step simulated time, deterministic
/// (issue 37, docs/closed_loop.md): the simulated quadrotor, its sensors, the estimator, calibrator
/// and mission nodes, and the controller on the estimate. Writes closed_loop.yaml, truth.csv,
/// estimate.csv, planned.csv, anchors.csv, calibration.yaml into --out.

#include <spdlog/spdlog.h>

#include <filesystem>
#include <iostream>

#include "closed_loop/closed_loop.h"
#include "closed_loop/closed_loop_io.h"
#include "common/cli_main.h"
#include "common/yaml_options.h"
#include "estimator/core/estimator_options.h"
#include "mission/mission.h"
#include "sim/sensor_fault_cli.h"

using namespace meshnav;

namespace {

constexpr char kDescription[] =
    "Flies a mission in closed loop (docs/closed_loop.md): a simulated quadrotor in the paper's hall with its IMU, "
    "barometer and meshed UWB ranges, the estimator, calibrator and mission nodes, and the controller that flies "
    "the mission's waypoints on the estimated POSE only. Lock-step simulated time, deterministic for a seed. "
    "Exit status 0: landed without a crash; 1: a file failed; 2: bad command line; 3: crashed or not landed.";

struct FlyOptions {
  std::string mission = "config/missions/paper_like_closed_loop.yaml";
  std::string out, config, controller_config, vehicle_config, calib_config, strategy;
  uint64_t seed = 1;
  double max_duration_s = 400.0;
  double gust_sigma_m_s = 0.0;
  std::vector<double> pose_outage;
  sim::SensorFaultArgs faults;
  bool print_config = false;
};

void declareOptions(Cli& cli, FlyOptions& o) {
  cli.option("mission", o.mission, "mission file with a 'flight' (waypoints) and calibrate steps")->type_name("FILE");
  cli.optional("out", o.out, "output folder (created)")->type_name("DIR")->required();
  cli.option("seed", o.seed, "sequence seed: IMU, baro and range noise, pad prior as `meshnav sim --seed`");
  cli.optional("config", o.config, "estimator options YAML (default: built-in = config/estimator.yaml)")
      ->type_name("FILE");
  cli.optional("strategy", o.strategy, "fusion strategy (default: the config's)");
  cli.optional("controller-config", o.controller_config, "controller options YAML (default: config/controller.yaml's values)")
      ->type_name("FILE");
  cli.optional("vehicle-config", o.vehicle_config, "vehicle dynamics YAML (sim/quadrotor_dynamics.h; default built-in)")
      ->type_name("FILE");
  cli.optional("calib-config", o.calib_config, "calibrator options YAML (default: built-in)")->type_name("FILE");
  cli.option("max-duration", o.max_duration_s, "stop after this much simulated time [s]");
  cli.option("gust-sigma", o.gust_sigma_m_s, "wind gusts: sigma per axis [m/s] (0: calm)");
  cli.optional("pose-outage", o.pose_outage,
               "failsafe drill: withhold POSE from the controller from A to B seconds (--pose-outage A,B)")
      ->delimiter(',')
      ->expected(2);
  sim::declareSensorFaultOptions(cli, o.faults, /*with_imu_gap=*/true);
  cli.flag("print-config", o.print_config, "print the controller and vehicle options and exit");
}

int run(const FlyOptions& o) {
  closed_loop::ClosedLoopOptions opts;
  opts.controller = controller::ControllerOptions::load(o.controller_config);
  if (!o.vehicle_config.empty()) {
    opts.vehicle.dynamics = sim::QuadrotorOptions::fromYaml(YamlOptions::loadFile(o.vehicle_config), o.vehicle_config);
  }
  opts.vehicle.dynamics.gust_sigma_m_s = std::max(opts.vehicle.dynamics.gust_sigma_m_s, o.gust_sigma_m_s);
  if (o.print_config) {
    std::cout << "controller:\n" << opts.controller.toString() << "vehicle:\n" << opts.vehicle.dynamics.toString();
    return 0;
  }
  opts.mission = mission::loadMission(o.mission);
  opts.vehicle.sensors.seed = o.seed;
  opts.pipeline.estimator = o.config.empty() ? estimator::EstimatorOptions{} : estimator::EstimatorOptions::fromYaml(o.config);
  if (!o.strategy.empty()) opts.pipeline.estimator.strategy = o.strategy;
  opts.calibrator_config = o.calib_config;
  opts.max_duration_s = o.max_duration_s;
  if (o.pose_outage.size() == 2) opts.pose_outages_s.push_back({o.pose_outage[0], o.pose_outage[1]});
  opts.faults = o.faults.options();
  opts.progress = [](double t) {
    if (static_cast<int>(t) % 20 == 0) spdlog::info("t = {:.0f} s", t);
  };
  spdlog::info("closed loop: mission {}, seed {}, strategy {}, faults: {}", o.mission, o.seed,
               opts.pipeline.estimator.strategy, opts.faults.toString());
  closed_loop::ClosedLoop loop(opts);
  const closed_loop::ClosedLoopResult r = loop.run();
  closed_loop::writeClosedLoopOutputs(r, o.out, o.seed, o.mission);
  const auto& m = r.metrics;
  spdlog::info("tracking RMSE {:.3f} m, estimation RMSE {:.3f} m (max {:.3f} m), {}, landed within {:.3f} m of the "
               "pad, {} failsafe events, flight {:.1f} s; anchors {:.3f} -> {:.3f} m; results in {}",
               m.tracking_rmse_m, m.estimation_rmse_m, m.max_estimation_error_m,
               m.crashed ? "CRASHED (" + m.crash_reason + ")" : std::string("no crash"), m.landed_within_m,
               m.failsafe_events, m.flight_time_s, m.anchors_initial_mean_m, m.anchors_final_mean_m, o.out);
  spdlog::info("estimator counters: {}", r.estimator_summary);
  if (opts.faults.any())
    spdlog::info("faults: {} ({} IMU samples, {} ranges taken away)", r.faults, r.imu_dropped, r.ranges_dropped);
  if (m.crashed || !m.landed) {
    spdlog::error("the flight ended {}", m.crashed ? "in a crash" : "without landing");
    return 3;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return cliMain<FlyOptions>(argc, argv, "meshnav_fly", kDescription, declareOptions,
                             [](const Cli&, FlyOptions& o) { return run(o); });
}
