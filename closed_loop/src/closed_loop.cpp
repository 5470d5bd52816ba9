#include "closed_loop/closed_loop.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <unordered_map>

#include "calibrator/node/calibrator_config.h"
#include "estimator/node/estimator_input.h"

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

ClosedLoop::ClosedLoop(ClosedLoopOptions options) : options_(std::move(options)) {
  if (!options_.mission.flight)
    throw std::invalid_argument(options_.mission.source + ": the mission has no 'flight' (waypoints) to fly");
  const auto& f = *options_.mission.flight;
  // Every point of the plan inside the hall: a waypoint in a wall is a crash, not a flight.
  const sim::QuadrotorOptions& dyn = options_.vehicle.dynamics;
  const auto inside = [&](const Eigen::Vector3d& p) {
    return (p - dyn.hall_min_m).minCoeff() > 0.0 && (dyn.hall_max_m - p).minCoeff() > 0.0;
  };
  const auto where = [&](int line) {
    return options_.mission.source + (line > 0 ? ":" + std::to_string(line) : std::string());
  };
  if (!inside(Eigen::Vector3d(f.pad_xy_m.x(), f.pad_xy_m.y(), f.takeoff_height_m)))
    throw std::invalid_argument(where(0) + ": key 'flight.pad' / 'flight.takeoff_height' is outside the hall");
  for (size_t i = 0; i < f.waypoints.size(); ++i)
    if (!inside(f.waypoints[i].p_IinG))
      throw std::invalid_argument(where(f.waypoints[i].line) + ": key 'flight.waypoints[" + std::to_string(i) +
                                  "].p' is outside the hall");
  options_.vehicle.pad_p_m = Eigen::Vector3d(f.pad_xy_m.x(), f.pad_xy_m.y(), 0.0);
  options_.vehicle.pad_yaw_rad = f.pad_yaw_deg * std::numbers::pi / 180.0;
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
  struct TruthAt {
    Eigen::Vector3d p;
    bool airborne;
  };
  std::unordered_map<int64_t, TruthAt> truth_at;
  std::optional<double> touchdown_s;
  double next_progress_s = 1.0;

  const auto take = [&](const sim::VehicleOutputs& out) {
    for (const auto& t : out.truth) truth_at[t.t.us] = {t.p_IinG, !vehicle.dynamics().landed()};
    for (const auto& in : inputsOf(out)) pipe.onInput(in);
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
  ClosedLoopMetrics& m = res.metrics;
  m.duration_s = vehicle.time();
  m.crashed = vehicle.dynamics().crashed();
  m.crash_reason = vehicle.dynamics().crashReason();
  m.landed = vehicle.dynamics().landed() && ctrl.mode() == controller::ControlMode::Landed;
  m.mission_complete = ctrl.status().mission_complete;
  m.failsafe_events = ctrl.status().failsafe_events;
  const Eigen::Vector3d p_end = vehicle.dynamics().state().p_IinG;
  if (m.landed) m.landed_within_m = (p_end - res.pad).head<2>().norm();
  double sum_e2 = 0.0;
  size_t n_e = 0;
  for (const auto& [t_us, idx] : estimate_at) {
    const auto it = truth_at.find(t_us);
    if (it == truth_at.end() || !it->second.airborne) continue;
    const double e = (res.estimates[idx].p_IinG - it->second.p).norm();
    sum_e2 += e * e;
    ++n_e;
    m.max_estimation_error_m = std::max(m.max_estimation_error_m, e);
  }
  m.estimation_rmse_m = n_e ? std::sqrt(sum_e2 / static_cast<double>(n_e)) : 0.0;
  double sum_t2 = 0.0;
  size_t n_t = 0, n_air = 0;
  for (const auto& s : res.samples) {
    n_air += s.airborne ? 1 : 0;
    if (!s.airborne || s.status.mode != controller::ControlMode::Flying) continue;
    if (s.status.phase != "takeoff" && s.status.phase != "waypoints" && s.status.phase != "return") continue;
    sum_t2 += (s.p_true - s.status.setpoint.p_IinG).squaredNorm();
    ++n_t;
  }
  m.tracking_rmse_m = n_t ? std::sqrt(sum_t2 / static_cast<double>(n_t)) : 0.0;
  if (res.samples.size() > 1)
    m.flight_time_s = static_cast<double>(n_air) * (res.samples[1].t_s - res.samples[0].t_s);

  // Anchors: the calibration's initial beliefs and the estimator's last ones.
  res.anchor_inits = pipe.anchorInits();
  if (pipe.calibrator()) res.calibration = pipe.calibrator()->results();
  if (pipe.estimator().initialized()) res.final_anchors = pipe.estimator().anchors();
  std::map<SensorId, AnchorResult> anchors;
  for (const auto& a : res.anchor_inits) {
    const auto it = res.truth.anchor_positions.find(a.id);
    if (it == res.truth.anchor_positions.end()) continue;
    anchors[a.id].id = a.id;
    anchors[a.id].initial_error_m = (a.p_AinG - it->second).norm();
  }
  for (const auto& a : res.final_anchors)
    if (anchors.count(a.id)) anchors[a.id].final_error_m = (a.p_AinG - res.truth.anchor_positions.at(a.id)).norm();
  double s0 = 0.0, s1 = 0.0;
  int n0 = 0, n1 = 0;
  for (const auto& [id, a] : anchors) {
    m.anchors.push_back(a);
    if (a.initial_error_m >= 0.0) s0 += a.initial_error_m, ++n0;
    if (a.final_error_m >= 0.0) s1 += a.final_error_m, ++n1;
  }
  if (n0) m.anchors_initial_mean_m = s0 / n0;
  if (n1) m.anchors_final_mean_m = s1 / n1;
  std::string counters;
  for (const auto& [k, v] : pipe.estimator().status().counters) counters += k + "=" + std::to_string(v) + " ";
  res.estimator_summary = counters;
  return res;
}

}  // namespace meshnav::closed_loop
