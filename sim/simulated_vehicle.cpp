#include "sim/simulated_vehicle.h"

#include <cmath>
#include <stdexcept>

#include "sim/random_stream.h"
#include "sim/scenario_builder.h"
#include "sim/scenario_simulator.h"
#include "sim/trajectory.h"

namespace meshnav::sim {

namespace {

/// The vehicle resting on its pad: what makeSetup draws the pad prior around.
class PadTrajectory : public Trajectory {
 public:
  PadTrajectory(const Eigen::Vector3d& p, double yaw) : p_(p), yaw_(yaw) {}
  TrajectoryState evaluate(double t_s) const override {
    TrajectoryState s;
    s.t_s = t_s;
    s.p_IinG = p_;
    s.R_ItoG = Eigen::AngleAxisd(yaw_, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    s.q_ItoG = Eigen::Quaterniond(s.R_ItoG);
    s.yaw_rad = yaw_;
    return s;
  }
  double duration() const override { return 0.0; }
  bool isLanded(double) const override { return true; }
  bool hasLandedPhase() const override { return true; }
  std::string kind() const override { return "pad"; }
  std::string toString() const override { return "resting on the pad"; }

 private:
  Eigen::Vector3d p_;
  double yaw_;
};

}  // namespace

SimulatedVehicle::SimulatedVehicle(const SimulatedVehicleOptions& options, std::optional<PaperScenario> scenario)
    : options_(options),
      scenario_(scenario ? std::move(*scenario) : buildScenario(options.sensors)),
      pad_(options.pad_p_m.x(), options.pad_p_m.y(), options.dynamics.pad_height_m),
      dyn_(options.dynamics, pad_, options.pad_yaw_rad, options.sensors.seed),
      imu_(options.sensors.imu, options.sensors.seed) {
  const SimulationOptions& o = options_.sensors;
  o.validate();
  const double ratio = options_.dynamics.integration_rate_hz / o.imu.rate_hz;
  if (std::abs(ratio - std::round(ratio)) > 1e-9 || ratio < 1.0)
    throw std::invalid_argument("SimulatedVehicle: the IMU rate (" + std::to_string(o.imu.rate_hz) +
                                " Hz) must divide the integration rate (" +
                                std::to_string(options_.dynamics.integration_rate_hz) + " Hz)");
  steps_per_imu_ = static_cast<int64_t>(std::llround(ratio));
  // The same seeded draws as ScenarioSimulator::run: reference pressure, TDMA phase, hardware.
  RandomStream rng_ref(RandomStream::deriveSeed(o.seed, "baro_reference"));
  BaroOptions baro = o.baro;
  baro.reference_pressure_pa =
      o.reference_pressure_mean_pa + rng_ref.uniform(-o.reference_pressure_spread_pa, o.reference_pressure_spread_pa);
  baro.p_IP = scenario_.baro_p_IP;
  baro_.emplace(baro, o.seed);
  RandomStream rng_tdma(RandomStream::deriveSeed(o.seed, "tdma_phase"));
  const double t0 = std::round(rng_tdma.uniform(0.0, o.uwb.slot_s) * 1e6) * 1e-6;
  schedule_.emplace(scenario_.uwbDeviceIds(), o.uwb.slot_s, t0);
  biases_.emplace(scenario_.uwbDeviceIds(), o.hardware);
  uwb_.emplace(scenario_, *biases_, o.uwb, o.seed);
  imu_.start(true);

  const PadTrajectory pad_trajectory(pad_, options_.pad_yaw_rad);
  setup_ = makeSetup(o, scenario_, pad_trajectory, *biases_, baro);
  truth_.anchor_positions = scenario_.anchors_p_AinG;
  truth_.pair_biases = biases_->allTrue(o.uwb.sigma_range_m);
  truth_.scalars["seed"] = static_cast<double>(o.seed);
  truth_.scalars["baro_reference_pressure_pa"] = baro.reference_pressure_pa;
  truth_.scalars["tdma_t0_s"] = t0;
  for (int i = 0; i < 3; ++i) {
    truth_.scalars[std::string("imu_acc_bias0_") + "xyz"[i]] = imu_.initialAccBias()[i];
    truth_.scalars[std::string("imu_gyro_bias0_") + "xyz"[i]] = imu_.initialGyroBias()[i];
  }
  cur_ = prev_ = dyn_.state();
}

TrajectoryState SimulatedVehicle::stateAt(double t_s) const {
  const double span = cur_.t_s - prev_.t_s;
  const double u = span > 0.0 ? std::clamp((t_s - prev_.t_s) / span, 0.0, 1.0) : 1.0;
  TrajectoryState s = u >= 1.0 ? cur_ : prev_;
  s.t_s = t_s;
  s.p_IinG = prev_.p_IinG + u * (cur_.p_IinG - prev_.p_IinG);
  s.v_IinG = prev_.v_IinG + u * (cur_.v_IinG - prev_.v_IinG);
  s.q_ItoG = prev_.q_ItoG.slerp(u, cur_.q_ItoG);
  s.R_ItoG = s.q_ItoG.toRotationMatrix();
  return s;
}

VehicleOutputs SimulatedVehicle::start() {
  VehicleOutputs out;
  sampleDue(out);
  return out;
}

VehicleOutputs SimulatedVehicle::step() {
  prev_ = cur_;
  dyn_.step();
  cur_ = dyn_.state();
  VehicleOutputs out;
  sampleDue(out);
  return out;
}

void SimulatedVehicle::sampleDue(VehicleOutputs& out) {
  const SimulationOptions& o = options_.sensors;
  const double t = dyn_.time();
  const bool airborne = !dyn_.landed();
  // IMU on its grid (k / rate lies on a step: the rate divides the integration rate).
  if (dyn_.stepIndex() % steps_per_imu_ == 0) {
    TrajectoryState st = cur_;
    st.t_s = static_cast<double>(n_imu_) / o.imu.rate_hz;
    ++n_imu_;
    out.imu.push_back(imu_.sample(st, airborne));
    out.truth.push_back({Timestamp::fromSec(st.t_s), st.p_IinG, st.q_ItoG});
  }
  // Baro on its grid: the state at the step nearest its time.
  for (double tb = static_cast<double>(n_baro_) / o.baro.rate_hz; tb <= t + 0.5 * dyn_.stepSize();
       tb = static_cast<double>(n_baro_) / o.baro.rate_hz) {
    ++n_baro_;
    TrajectoryState st = stateAt(tb);
    out.baro.push_back(baro_->sample(st));
  }
  for (double tf = static_cast<double>(n_flight_) / o.flight_state_rate_hz; tf <= t + 0.5 * dyn_.stepSize();
       tf = static_cast<double>(n_flight_) / o.flight_state_rate_hz) {
    ++n_flight_;
    out.flight_states.push_back({Timestamp::fromSec(tf), dyn_.landed()});
  }
  out.ranges = uwb_->simulateUntil([this](double ts) { return stateAt(ts); }, *schedule_, t);
}

}  // namespace meshnav::sim
