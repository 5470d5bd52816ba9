/// controller: the ControllerNode (controller/controller_node.h) on LCM, scheduled by ControlLoop
/// (controller/control_loop.h): POSE, IMU, FLIGHT_STATE -> CONTROL_CMD, CONTROL_STATUS.
/// CONTROL_STATUS goes out at --status-rate of data time and, as the heartbeat, every --heartbeat
/// seconds of wall time (also before any data, so that vehicle_sim can wait for the controller).
#include <chrono>
#include <fstream>
#include <iostream>

#include "controller/control_loop.h"
#include "controller/controller_node.h"
#include "controller/controller_options.h"
#include "controller/loop_jitter.h"
#include "controller/process/control_messages.h"
#include "mission/mission.h"
#include "transport/channels.h"
#include "transport/latency_recorder.h"
#include "transport/process_main.h"

namespace {

using namespace meshnav;

struct ControllerProcessOptions {
  std::string mission_path, config_path, timing_out;
  double status_rate_hz = 10.0, heartbeat_s = 1.0;
  bool print_config = false;
};

void declareOptions(Cli& cli, ControllerProcessOptions& o) {
  cli.optional("mission", o.mission_path, "mission file whose 'flight' (pad, waypoints) is flown; required")
      ->type_name("FILE");
  cli.optional("config", o.config_path, "controller options YAML (default: built-in = config/controller.yaml)")
      ->type_name("FILE");
  cli.option("status-rate", o.status_rate_hz, "CONTROL_STATUS rate in data time [Hz] (0: at every update)")
      ->type_name("HZ")
      ->check(cli::nonNegative());
  cli.option("heartbeat", o.heartbeat_s, "wall seconds between heartbeat CONTROL_STATUS")->type_name("S")->check(cli::positive());
  cli.optional("timing-out", o.timing_out, "write the loop jitter (p50, p99, max) and counts as YAML here at exit")
      ->type_name("FILE");
  cli.flag("print-config", o.print_config, "print the controller options and exit");
}

}  // namespace

int main(int argc, char** argv) {
  transport::ProcessMain process(
      "controller",
      "Flies the 'flight' of a mission file on the estimated POSE only (docs/closed_loop.md): subscribes POSE, IMU, "
      "FLIGHT_STATE; publishes CONTROL_CMD (thrust and body rates, stamped with the IMU sample it answers: one per "
      "POSE, or per IMU sample while no POSE comes) and CONTROL_STATUS (mode, failsafe events and reason, setpoint, "
      "loop jitter). Failsafe when POSE is late or its covariance too large.");
  return process.run<ControllerProcessOptions>(argc, argv, declareOptions, [&](ControllerProcessOptions& o) {
    const controller::ControllerOptions options = controller::ControllerOptions::load(o.config_path);
    if (o.print_config) {
      std::cout << options.toString();
      return 0;
    }
    process.require(!o.mission_path.empty(), "mission");
    const mission::Mission m = mission::loadMission(o.mission_path);
    if (!m.flight) throw std::runtime_error(o.mission_path + ": the mission has no 'flight' (waypoints) to fly");
    transport::LcmNode& lcm = process.lcm();

    controller::LoopJitter jitter;      // of the updates (monotonic clock)
    controller::LoopJitter imu_jitter;  // of the IMU samples' arrival (LCM's receive time)
    // Where the time goes: IMU → POSE (estimator and two hops) and IMU → CONTROL_CMD (out of here),
    // both from the receive time of the IMU sample here (transport/latency_recorder.h).
    transport::LatencyRecorder to_pose, to_cmd;
    int64_t updates = 0;
    const auto statusMsg = [&](const controller::ControlStatus& s) {
      return controller::toLcm(s, updates, jitter.quantileMs(0.99), jitter.maxMs());
    };
    controller::ControllerSinks sinks;
    sinks.status = [&](const controller::ControlStatus& s) {
      control_status_t msg = statusMsg(s);
      msg.wall_utime = replay::wallUtimeNow();
      lcm.publish(channels::kControlStatus, msg);
    };
    controller::ControllerNode node(options, *m.flight, sinks, o.status_rate_hz);
    controller::ControlLoop loop(node, options.pose_timeout_s, [&](const controller::ControlCommand& c) {
      jitter.add(c.t.us, replay::monotonicUsNow());
      ++updates;
      lcm.publish(channels::kControlCmd, controller::toLcm(c, node.mode()));
      to_cmd.onPose(c.t.us, replay::wallUtimeNow());
    });
    lcm.subscribeStamped(channels::kPose, [&](const PoseEstimate& p, int64_t recv_utime) {
      to_pose.onPose(p.t.us, recv_utime);
      loop.onPose(p);
    });
    lcm.subscribeStamped(channels::kImu, [&](const ImuSample& s, int64_t recv_utime) {
      imu_jitter.add(s.t.us, recv_utime);
      to_pose.onImu(s.t.us, recv_utime);
      to_cmd.onImu(s.t.us, recv_utime);
      loop.onImu(s.t);
    });
    lcm.subscribe(channels::kFlightState, [&](const FlightStateSample& fs) { loop.onFlightState(fs); });
    lcm.setHeartbeat(Duration::fromSec(o.heartbeat_s), [&] {
      control_status_t msg = statusMsg(node.status());
      msg.wall_utime = replay::wallUtimeNow();
      lcm.publish(channels::kControlStatus, msg);
    });
    spdlog::info("controller options:\n{}", options.toString());
    spdlog::info("LCM {}; mission {} ({} waypoints); waiting for data", lcm.url(), o.mission_path,
                 m.flight->waypoints.size());
    const int rc = lcm.spin();
    const controller::ControlStatus& st = node.status();
    spdlog::info("stopped at t = {} s: mode {}, {} updates ({} on IMU), {} failsafe events, loop jitter p99 {:.3f} ms, "
                 "max {:.3f} ms; counters: {}",
                 formatSeconds(st.t), controller::toString(st.mode), loop.updates(), loop.imuUpdates(),
                 st.failsafe_events, jitter.quantileMs(0.99), jitter.maxMs(),
                 transport::formatCounters(lcm.diagnostics().snapshot()));
    if (!o.timing_out.empty()) {
      std::ofstream f(o.timing_out);
      f << "# controller loop: |wall interval - data interval| between consecutive updates\n"
        << "updates: " << loop.updates() << "\nimu_updates: " << loop.imuUpdates() << "\nintervals: " << jitter.count()
        << "\njitter_p50_ms: " << jitter.quantileMs(0.5) << "\njitter_p99_ms: " << jitter.quantileMs(0.99)
        << "\njitter_max_ms: " << jitter.maxMs() << "\nfailsafe_events: " << st.failsafe_events << "\n";
      // The same measure of the IMU samples' arrival (what the vehicle and the bus give the loop),
      // and the latencies from an IMU sample's arrival [ms].
      const auto ms = [](const transport::LatencyStats& l) {
        return fmt::format("{{n: {}, p50: {:.3f}, p99: {:.3f}, max: {:.3f}}}", l.n, l.median_us / 1e3, l.p99_us / 1e3,
                           l.max_us / 1e3);
      };
      f << "imu_arrival_jitter_p50_ms: " << imu_jitter.quantileMs(0.5)
        << "\nimu_arrival_jitter_p99_ms: " << imu_jitter.quantileMs(0.99)
        << "\nimu_arrival_jitter_max_ms: " << imu_jitter.maxMs() << "\nimu_to_pose_ms: " << ms(to_pose.imuToPose())
        << "\nimu_to_cmd_ms: " << ms(to_cmd.imuToPose()) << "\n";
      if (!f) spdlog::error("{}: cannot write", o.timing_out);
    }
    return rc;
  });
}
