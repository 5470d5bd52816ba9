/// vehicle_sim: the simulated quadrotor (sim/vehicle_sim_node.h) on LCM (docs/closed_loop.md,
/// "Over LCM"). CONTROL_CMD -> IMU, BARO, RANGE, FLIGHT_STATE, GROUND_TRUTH.
/// Lock-step by default: after each step that published an IMU sample it waits for the
/// CONTROL_CMD stamped with it (--command-timeout of wall time: counted late, the last command
/// kept). --realtime paces the steps by the wall clock and waits for nothing. With --out it also
/// evaluates the flight (the truth is its own): POSE, CONTROL_STATUS, ANCHOR_INIT and ANCHORS
/// against the truth, into closed_loop.yaml and the files of `meshnav fly`.
#include <chrono>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <thread>

#include "closed_loop/closed_loop.h"
#include "closed_loop/closed_loop_io.h"
#include "closed_loop/flight_recorder.h"
#include "common/setup.h"
#include "common/yaml_options.h"
#include "controller/process/control_messages.h"
#include "mission/mission.h"
#include "sim/sensor_fault_cli.h"
#include "sim/vehicle_sim_node.h"
#include "transport/channels.h"
#include "transport/process_main.h"

namespace {

using namespace meshnav;

struct VehicleSimProcessOptions {
  std::string mission = "config/missions/paper_like_closed_loop.yaml";
  std::string vehicle_config, out, write_setup;
  uint64_t seed = 1;
  bool realtime = false, print_config = false;
  double speed = 1.0, command_timeout_s = 0.05, max_duration_s = 400.0, after_touchdown_s = 2.0;
  double gust_sigma_m_s = 0.0, progress_s = 10.0, wait_timeout_s = 60.0;
  std::vector<std::string> wait_for = {"ESTIMATOR_STATUS", "CONTROL_STATUS"};
  sim::SensorFaultArgs faults;  ///< no --imu-gap: the controller's clock is the IMU stream here
};

void declareOptions(Cli& cli, VehicleSimProcessOptions& o) {
  cli.option("mission", o.mission, "mission file: its 'flight' gives the pad and heading (and is checked against the hall)")
      ->type_name("FILE");
  cli.option("seed", o.seed, "sequence seed: IMU, baro and range noise, pad prior as `meshnav sim --seed`");
  cli.optional("vehicle-config", o.vehicle_config, "vehicle dynamics YAML (sim/quadrotor_dynamics.h; default built-in)")
      ->type_name("FILE");
  cli.option("gust-sigma", o.gust_sigma_m_s, "wind gusts: sigma per axis [m/s] (0: calm)")->check(cli::nonNegative());
  cli.flag("realtime", o.realtime, "pace the simulation by the wall clock (× --speed) and wait for no command");
  cli.option("speed", o.speed, "with --realtime: simulated seconds per wall second")->check(cli::positive());
  cli.option("command-timeout", o.command_timeout_s,
             "lock-step: wall seconds to wait for the CONTROL_CMD answering an IMU sample (then counted late, the "
             "last command kept)")
      ->type_name("S")
      ->check(cli::positive());
  cli.option("max-duration", o.max_duration_s, "stop after this much simulated time [s]")->check(cli::positive());
  cli.option("after-touchdown", o.after_touchdown_s, "keep running this long after the controller reported landed [s]");
  cli.option("wait-for", o.wait_for, "channels heard once before the first sample (the processes are up)")
      ->delimiter(',');
  cli.option("wait-timeout", o.wait_timeout_s, "wall seconds to wait for each --wait-for channel (then exit 1)")
      ->check(cli::positive());
  cli.option("progress", o.progress_s, "simulated seconds between progress lines ('t = N s')")->check(cli::positive());
  cli.optional("out", o.out, "evaluate the flight into this folder (closed_loop.yaml, truth.csv, estimate.csv, ...)")
      ->type_name("DIR");
  cli.optional("write-setup", o.write_setup, "write setup.yaml and truth.yaml of --seed into DIR and exit")
      ->type_name("DIR");
  sim::declareSensorFaultOptions(cli, o.faults, /*with_imu_gap=*/false);
  cli.flag("print-config", o.print_config, "print the vehicle options and exit");
}

}  // namespace

int main(int argc, char** argv) {
  transport::ProcessMain process(
      "vehicle_sim",
      "Simulated quadrotor in the paper's hall for the closed loop (docs/closed_loop.md): publishes IMU (200 Hz), BARO, "
      "RANGE (meshed TDMA, NLOS, outliers), FLIGHT_STATE (contact switch) and GROUND_TRUTH, and flies the CONTROL_CMD "
      "of the controller. Lock-step simulated time by default (waits for the command answering each IMU sample); "
      "--realtime paces it by the wall clock. Exit status 0: landed without a crash; 3: crashed or not landed; "
      "1: a failure; 2: bad command line.");
  return process.run<VehicleSimProcessOptions>(argc, argv, declareOptions, [&](VehicleSimProcessOptions& o) -> int {
    sim::VehicleSimNodeOptions options;
    if (!o.vehicle_config.empty())
      options.vehicle.dynamics =
          sim::QuadrotorOptions::fromYaml(YamlOptions::loadFile(o.vehicle_config), o.vehicle_config);
    options.vehicle.dynamics.gust_sigma_m_s = std::max(options.vehicle.dynamics.gust_sigma_m_s, o.gust_sigma_m_s);
    options.vehicle.sensors.seed = o.seed;
    options.max_duration_s = o.max_duration_s;
    options.after_touchdown_s = o.after_touchdown_s;
    options.faults = o.faults.options();
    if (o.print_config) {
      std::cout << "vehicle:\n" << options.vehicle.dynamics.toString() << "faults: " << options.faults.toString() << "\n";
      return 0;
    }
    const mission::Mission m = mission::loadMission(o.mission);
    closed_loop::applyFlightPlan(m, options.vehicle);

    transport::LcmNode* lcm = nullptr;
    std::optional<closed_loop::FlightRecorder> recorder;
    sim::VehicleSimSinks sinks;
    sinks.imu = [&](const ImuSample& s) { lcm->publish(channels::kImu, s); };
    sinks.baro = [&](const BaroSample& s) { lcm->publish(channels::kBaro, s); };
    sinks.range = [&](const RangeSample& s) { lcm->publish(channels::kRange, s); };
    sinks.flight_state = [&](const FlightStateSample& s) { lcm->publish(channels::kFlightState, s); };
    sinks.truth = [&](const PoseSample& p, bool airborne) {
      lcm->publish(channels::kGroundTruth, p);
      if (recorder) recorder->onTruth(p.t, p.p_IinG, p.q_ItoG, airborne);
    };
    sim::VehicleSimNode node(options, sinks);
    if (!o.write_setup.empty()) {
      std::filesystem::create_directories(o.write_setup);
      saveSetup(node.vehicle().setup(), (std::filesystem::path(o.write_setup) / "setup.yaml").string());
      saveTruth(node.vehicle().truth(), (std::filesystem::path(o.write_setup) / "truth.yaml").string());
      spdlog::info("setup.yaml and truth.yaml of seed {} in {}", o.seed, o.write_setup);
      return 0;
    }
    lcm = &process.lcm();
    if (!o.out.empty()) recorder.emplace(node.vehicle().setup(), node.vehicle().truth(), node.vehicle().pad());

    lcm->subscribe(channels::kControlCmd, [&](const control_cmd_t& c) {
      if (const std::string why = controller::invalidReason(c); !why.empty()) {
        lcm->diagnostics().report("CONTROL_CMD:invalid_message", "CONTROL_CMD dropped: " + why);
        return;
      }
      node.onCommand(Timestamp{c.utime}, {c.thrust_m_s2, Eigen::Vector3d(c.w_IinI[0], c.w_IinI[1], c.w_IinI[2])},
                     controller::modeOf(c.mode) == controller::ControlMode::Landed);
    });
    // CONTROL_STATUS (one subscription: a malformed message is counted once): mode changes and
    // failsafe events logged (what a drill shows), and the evaluation's controller samples.
    controller::ControlStatus shown;
    lcm->subscribe(channels::kControlStatus, [&](const control_status_t& m) {
      if (const std::string why = controller::invalidReason(m); !why.empty()) {
        lcm->diagnostics().report("CONTROL_STATUS:invalid_message", "CONTROL_STATUS dropped: " + why);
        return;
      }
      const controller::ControlStatus s = controller::fromLcm(m);
      if (s.mode != shown.mode || s.failsafe_events != shown.failsafe_events)
        spdlog::info("CONTROL_STATUS t = {} s: {} -> {}{}, failsafe events {}", formatSeconds(s.t),
                     controller::toString(shown.mode), controller::toString(s.mode),
                     s.mode == controller::ControlMode::Failsafe ? " (" + s.failsafe_reason + ")" : std::string(),
                     s.failsafe_events);
      shown = s;
      if (recorder) recorder->onControlStatus(s);
    });
    if (recorder) {
      lcm->subscribe(channels::kPose, [&](const PoseEstimate& e) { recorder->onPose(e); });
      lcm->subscribe(channels::kAnchorInit, [&](const AnchorInit& a) { recorder->onAnchorInit(a); });
      lcm->subscribe(channels::kAnchors, [&](const std::vector<AnchorEstimate>& a) { recorder->onAnchors(a); });
    }
    for (const std::string& ch : o.wait_for) {
      if (ch.empty()) continue;
      spdlog::info("waiting for {} (up to {} s)", ch, o.wait_timeout_s);
      if (!lcm->waitForMessage(ch, Duration::fromSec(o.wait_timeout_s))) {
        if (lcm->stopRequested()) return 1;
        spdlog::error("no {} within {} s: is its process running on {}?", ch, o.wait_timeout_s, lcm->url());
        return 1;
      }
    }
    spdlog::info("flying seed {} ({}), mission {}, faults: {}; LCM {}", o.seed,
                 o.realtime ? fmt::format("real time x{}", o.speed) : "lock-step", o.mission,
                 options.faults.toString(), lcm->url());

    const int64_t wall0 = replay::monotonicUsNow();
    double next_progress_s = o.progress_s;
    const int64_t timeout_us = static_cast<int64_t>(o.command_timeout_s * 1e6);
    node.start();
    while (!node.done() && !lcm->stopRequested()) {
      if (o.realtime) {
        // Commands that came in; then wait until the next step is due on the wall clock.
        while (lcm->spinOnce(0) > 0) {
        }
        const int64_t due_us = wall0 + static_cast<int64_t>((node.time() + 1e-3) / o.speed * 1e6);
        const int64_t wait_us = due_us - replay::monotonicUsNow();
        if (wait_us > 1000) {
          lcm->spinOnce(static_cast<int>(wait_us / 1000));
          continue;
        }
        if (wait_us > 0) std::this_thread::sleep_for(std::chrono::microseconds(wait_us));
      } else if (node.awaiting()) {
        const int64_t deadline = replay::monotonicUsNow() + timeout_us;
        while (node.awaiting() && !lcm->stopRequested()) {
          const int64_t left_us = deadline - replay::monotonicUsNow();
          if (left_us <= 0) break;
          if (lcm->spinOnce(static_cast<int>(std::max<int64_t>(1, left_us / 1000))) < 0) return 1;
        }
        if (node.awaiting()) node.commandLate();
      } else {
        while (lcm->spinOnce(0) > 0) {
        }
      }
      node.step();
      if (node.time() >= next_progress_s) {
        const auto& c = node.counters();
        spdlog::info("t = {:.0f} s ({:.1f} s wall): {} commands, {} late", node.time(),
                     static_cast<double>(replay::monotonicUsNow() - wall0) / 1e6, c.commands, c.commands_late);
        next_progress_s += o.progress_s;
      }
    }
    // The last POSE, CONTROL_STATUS and ANCHORS on their way: until 0.3 s of wall time pass without one.
    for (int quiet_ms = 0; quiet_ms < 300 && !lcm->stopRequested();) quiet_ms = lcm->spinOnce(50) > 0 ? 0 : quiet_ms + 50;
    const std::string why = node.endReason();
    const auto& c = node.counters();
    const auto& d = node.vehicle().dynamics();
    spdlog::info("stopped at t = {:.3f} s ({:.1f} s wall): {}; {} IMU, {} ranges published; {} commands, {} late, {} "
                 "stale; faults: {} ({} IMU dropped, {} ranges of the anchor off, {} ranges lost); counters: {}",
                 node.time(), static_cast<double>(replay::monotonicUsNow() - wall0) / 1e6, why.empty() ? "stopped" : why, c.imu,
                 c.ranges, c.commands, c.commands_late, c.commands_stale, options.faults.toString(),
                 node.faults().imuDropped(), node.faults().rangesAnchorOff(), node.faults().rangesLost(),
                 transport::formatCounters(lcm->diagnostics().snapshot()));
    const bool landed_ok = why == "landed" && d.landed();
    if (recorder) {
      closed_loop::FlightEnd end;
      end.duration_s = node.time();
      end.crashed = d.crashed();
      end.crash_reason = d.crashReason();
      end.landed = landed_ok;
      end.p_end = d.state().p_IinG;
      closed_loop::ClosedLoopResult r = recorder->finish(end);
      r.faults = options.faults.toString();
      r.ranges_dropped = node.faults().rangesAnchorOff() + node.faults().rangesLost();
      closed_loop::writeClosedLoopOutputs(r, o.out, o.seed, o.mission, /*with_calibration=*/false);
      const auto& mt = r.metrics;
      std::ofstream extra(std::filesystem::path(o.out) / "closed_loop.yaml", std::ios::app);
      extra << "over_lcm: true\nrealtime: " << (o.realtime ? "true" : "false") << "\ncommands_late: " << c.commands_late
            << "\ncommands_stale: " << c.commands_stale << "\nstatuses_without_truth: "
            << recorder->statusesWithoutTruth() << "\nfaults: \"" << r.faults << "\"\n";
      spdlog::info("tracking RMSE {:.3f} m, estimation RMSE {:.3f} m (max {:.3f} m), {}, landed within {:.3f} m of "
                   "the pad, {} failsafe events; anchors {:.3f} -> {:.3f} m; results in {}",
                   mt.tracking_rmse_m, mt.estimation_rmse_m, mt.max_estimation_error_m,
                   mt.crashed ? "CRASHED (" + mt.crash_reason + ")" : std::string("no crash"), mt.landed_within_m,
                   mt.failsafe_events, mt.anchors_initial_mean_m, mt.anchors_final_mean_m, o.out);
    }
    return landed_ok && !d.crashed() ? 0 : 3;
  });
}
