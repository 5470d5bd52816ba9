#include "closed_loop/closed_loop.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <unordered_map>

#include "calibrator/node/calibrator_config.h"
#include "closed_loop/closed_loop_metrics.h"
#include "estimator/node/estimator_input.h"
#include "sim/sensor_faults.h"

namespace meshnav::closed_loop {

namespace {

/// The vehicle's outputs of one step as estimator inputs, in the canonical order.
std::vector<estimator::EstimatorInput> inputsOf(const sim::VehicleOutputs& out) {
  std::vector<estimator::EstimatorInput> in;
  in.reserve(out.imu.size() + out.baro.size() + out.ranges.size() + out.flight_states.size());
  for (const auto& s : out.flight_states) in.emplace_back(s);
  for (const auto& s : out.imu) in.emplace_back(s);
  for (const auto& s : out.baro) in.emplace_back(s);
  for (const auto& r : out.ranges) in.emplace_back(r.sample);
  std::stable_sort(in.begin(), in.end(), [](const auto& a, const auto& b) {
    return estimator::inputOrder(a) < estimator::inputOrder(b);
  });
  return in;
}

}  // namespace

void applyFlightPlan(const mission::Mission& mission, sim::SimulatedVehicleOptions& vehicle) {
  if (!mission.flight) throw std::invalid_argument(mission.source + ": the mission has no 'flight' (waypoints) to fly");
  const auto& f = *mission.flight;
  // Every point of the plan inside the hall: a waypoint in a wall is a crash, not a flight.
  const sim::QuadrotorOptions& dyn = vehicle.dynamics;
  const auto inside = [&](const Eigen::Vector3d& p) {
    return (p - dyn.hall_min_m).minCoeff() > 0.0 && (dyn.hall_max_m - p).minCoeff() > 0.0;
  };
  const auto where = [&](int line) { return mission.source + (line > 0 ? ":" + std::to_string(line) : std::string()); };
  if (!inside(Eigen::Vector3d(f.pad_xy_m.x(), f.pad_xy_m.y(), f.takeoff_height_m)))
    throw std::invalid_argument(where(0) + ": key 'flight.pad' / 'flight.takeoff_height' is outside the hall");
  for (size_t i = 0; i < f.waypoints.size(); ++i)
    if (!inside(f.waypoints[i].p_IinG))
      throw std::invalid_argument(where(f.waypoints[i].line) + ": key 'flight.waypoints[" + std::to_string(i) +
                                  "].p' is outside the hall");
  vehicle.pad_p_m = Eigen::Vector3d(f.pad_xy_m.x(), f.pad_xy_m.y(), 0.0);
  vehicle.pad_yaw_rad = f.pad_yaw_deg * std::numbers::pi / 180.0;
}

ClosedLoop::ClosedLoop(ClosedLoopOptions options) : options_(std::move(options)) {
  applyFlightPlan(options_.mission, options_.vehicle);
}

ClosedLoopResult ClosedLoop::run() {
  ClosedLoopResult res;
  sim::SimulatedVehicle vehicle(options_.vehicle);
  res.setup = vehicle.setup();
  res.truth = vehicle.truth();
  res.pad = vehicle.pad();

  pipeline::PipelineOptions popts = options_.pipeline;
  popts.mission = options_.mission;
  calib::CalibratorConfig calib_config = calib::CalibratorConfig::load(options_.calibrator_config);
  calib_config.applySetup(res.setup);
  popts.calibrator = calib_config.calibrator;
  popts.calibrator_node = calib_config.node;

  controller::ControllerNode ctrl(options_.controller, *options_.mission.flight);
  const auto inOutage = [&](Timestamp t) {
    const double s = t.sec();
    for (const auto& [a, b] : options_.pose_outages_s)
      if (s >= a && s < b) return true;
    return false;
  };
  std::unordered_map<int64_t, size_t> estimate_at;  // POSE time [µs] → index of its first estimate
  pipeline::PipelineSinks sinks;
  sinks.pose = [&](size_t, const PoseEstimate& e) {
    if (!estimate_at.count(e.t.us)) estimate_at[e.t.us] = res.estimates.size();
    res.estimates.push_back(e);
    if (!inOutage(e.t)) ctrl.onPose(e);
  };
  pipeline::Pipeline pipe(popts, res.setup, sinks);

  // Truth at the IMU instants (what the estimates are compared with).
  TruthTimeline truth_at;
  sim::SensorFaults faults(options_.faults, options_.vehicle.sensors.seed);
  std::optional<double> touchdown_s;
  double next_progress_s = 1.0;

  const auto take = [&](const sim::VehicleOutputs& out) {
    for (const auto& t : out.truth) truth_at[t.t.us] = {t.p_IinG, !vehicle.dynamics().landed()};
    // The sensor faults of a drill act on the way to the pipeline; the controller keeps its clock.
    std::optional<sim::VehicleOutputs> sensed;
    if (faults.options().any()) faults.apply(sensed.emplace(out));
    for (const auto& in : inputsOf(sensed ? *sensed : out)) pipe.onInput(in);
    for (const auto& fs : out.flight_states) ctrl.onFlightState(fs);
    for (const auto& imu : out.imu) {
      // One controller step per IMU sample, right after its POSE.
      const controller::ControlCommand c = ctrl.update(imu.t);
      vehicle.setCommand({c.thrust_m_s2, c.w_IinI});
      ClosedLoopSample s;
      s.t_s = imu.t.sec();
      const sim::TrajectoryState st = vehicle.dynamics().state();
      s.p_true = st.p_IinG;
      s.q_true = st.q_ItoG;
      s.airborne = !vehicle.dynamics().landed();
      s.status = ctrl.status();
      res.samples.push_back(s);
    }
  };

  vehicle.setCommand({0.0, Eigen::Vector3d::Zero()});
  take(vehicle.start());
  while (vehicle.time() < options_.max_duration_s) {
    take(vehicle.step());
    if (vehicle.dynamics().crashed()) break;
    if (!touchdown_s && ctrl.mode() == controller::ControlMode::Landed) touchdown_s = vehicle.time();
    if (touchdown_s && vehicle.time() - *touchdown_s >= options_.after_touchdown_s) break;
    if (options_.progress && vehicle.time() >= next_progress_s) {
      options_.progress(vehicle.time());
      next_progress_s += 1.0;
    }
  }
  pipe.finish();

  // ---- metrics ----
  FlightEnd end;
  end.duration_s = vehicle.time();
  end.crashed = vehicle.dynamics().crashed();
  end.crash_reason = vehicle.dynamics().crashReason();
  end.landed = vehicle.dynamics().landed() && ctrl.mode() == controller::ControlMode::Landed;
  end.mission_complete = ctrl.status().mission_complete;
  end.failsafe_events = ctrl.status().failsafe_events;
  end.p_end = vehicle.dynamics().state().p_IinG;
  res.anchor_inits = pipe.anchorInits();
  if (pipe.calibrator()) res.calibration = pipe.calibrator()->results();
  if (pipe.estimator().initialized()) res.final_anchors = pipe.estimator().anchors();
  res.metrics = computeMetrics(res, truth_at, end);
  res.faults = faults.options().toString();
  res.imu_dropped = faults.imuDropped();
  res.ranges_dropped = faults.rangesAnchorOff() + faults.rangesLost();
  std::string counters;
  for (const auto& [k, v] : pipe.estimator().status().counters) counters += k + "=" + std::to_string(v) + " ";
  res.estimator_summary = counters;
  return res;
}

}  // namespace meshnav::closed_loop
