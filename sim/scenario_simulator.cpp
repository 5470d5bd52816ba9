#include "sim/scenario_simulator.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <numbers>

#include "sim/baro_simulator.h"
#include "sim/imu_simulator.h"
#include "sim/random_stream.h"
#include "sim/scenario_builder.h"
#include "sim/trajectory_factory.h"
#include "sim/tdma_schedule.h"
#include "sim/uwb_hardware_biases.h"
#include "sim/uwb_range_simulator.h"

namespace meshnav::sim {

namespace {
constexpr double kRadToDeg = 180.0 / std::numbers::pi;

/// Heading of I in G: angle of the projected x axis, ψ = atan2(R₁₀, R₀₀).
double yawOf(const Eigen::Matrix3d& R_ItoG) { return std::atan2(R_ItoG(1, 0), R_ItoG(0, 0)); }

/// Samples at t_k = k / rate for t_k ∈ [0, t_end].
int64_t sampleCount(double rate_hz, double t_end_s) {
  return static_cast<int64_t>(std::floor(t_end_s * rate_hz + 1e-9)) + 1;
}
}  // namespace

ScenarioSimulator::ScenarioSimulator(SimulationOptions options, std::optional<PaperScenario> scenario)
    : options_(std::move(options)) {
  options_.validate();
  scenario_ = scenario ? std::move(*scenario) : buildScenario(options_);
}

namespace {

/// What truth.yaml records beyond the dataset itself.
struct RunFacts {
  double t_end_s = 0.0;
  double tdma_t0_s = 0.0;
  double max_height_m = 0.0;
  size_t n_ranges = 0;
  const ImuSimulator* imu = nullptr;
  const UwbRangeSimulator* uwb = nullptr;
  BaroOptions baro;
};

}  // namespace

/// setup.yaml: what a user knows.
SystemSetup makeSetup(const SimulationOptions& o, const PaperScenario& scenario, const Trajectory& trajectory,
                      const UwbHardwareBiases& biases, const BaroOptions& baro_options) {
  SystemSetup setup;
  setup.imu_id = scenario.imu_id;
  setup.baro_id = scenario.baro_id;
  setup.rel_tag_positions = scenario.tags_p_TinI;
  for (SensorId id : scenario.known_anchor_ids) setup.abs_anchor_positions[id] = scenario.anchors_p_AinG.at(id);
  std::vector<SensorId> calibrated_ids;
  for (const auto& [id, p] : scenario.tags_p_TinI) calibrated_ids.push_back(id);
  for (SensorId id : scenario.known_anchor_ids) calibrated_ids.push_back(id);
  std::sort(calibrated_ids.begin(), calibrated_ids.end());
  for (size_t i = 0; i < calibrated_ids.size(); ++i)
    for (size_t j = i + 1; j < calibrated_ids.size(); ++j)
      setup.pair_biases.push_back(biases.calibrated(calibrated_ids[i], calibrated_ids[j], o.uwb.sigma_range_m));
  setup.baro_p_IP = scenario.baro_p_IP;
  // Taken on the ground at start when the flight starts landed; a flight starting in the air
  // cannot, so its reference is given.
  setup.baro_reference_pressure_pa.reset();
  if (!trajectory.hasLandedPhase() && trajectory.hasBarometer())
    setup.baro_reference_pressure_pa = baro_options.reference_pressure_pa;
  if (o.with_initial_pose && trajectory.hasLandedPhase()) {
    RandomStream rng_pose(RandomStream::deriveSeed(o.seed, "initial_pose"));
    const TrajectoryState st0 = trajectory.evaluate(0.0);
    InitialPose pose;
    pose.p_IinG = st0.p_IinG + rng_pose.gaussian3(o.initial_pose_sigma_p_m);
    pose.yaw_deg = yawOf(st0.R_ItoG) * kRadToDeg + rng_pose.gaussian(o.initial_pose_sigma_yaw_deg);
    pose.sigma_p_m = o.initial_pose_sigma_p_m;
    pose.sigma_yaw_deg = o.initial_pose_sigma_yaw_deg;
    setup.initial_pose = pose;
  }
  // A hand-held rig's user knows roughly how high it is carried: the walk holds it at 1.1–1.3 m
  // (± 0.05–0.12 m slowly, plus the gait's bob), said as 1.2 m ± 0.3 m.
  if (trajectory.isHandCarried()) setup.carried_height = CarriedHeight{1.2, 0.3};
  // The user knows the hall they fly in. Not written for the paper scenario, whose files stay as
  // they always were (its anchors are not coplanar, so the estimator would not use it).
  if (!o.isPaperScenario()) setup.flight_volume = FlightVolume{o.hall().min_m, o.hall().max_m};
  setup.noise.sigma_range_m = o.uwb.sigma_range_m;
  setup.noise.range_correlation_time_s = o.uwb.correlation_time_s;  // what the ranges were drawn with
  setup.noise.imu_acc_noise_density = o.imu.acc_noise_density;
  setup.noise.imu_gyro_noise_density = o.imu.gyro_noise_density;
  setup.noise.imu_acc_bias_rw = o.imu.acc_bias_rw;
  setup.noise.imu_gyro_bias_rw = o.imu.gyro_bias_rw;
  // The biases' switch-on spread, as a datasheet states it (absent for an ideal IMU).
  if (o.imu.acc_bias_initial_sigma > 0.0) setup.noise.imu_acc_bias_sigma = o.imu.acc_bias_initial_sigma;
  if (o.imu.gyro_bias_initial_sigma > 0.0) setup.noise.imu_gyro_bias_sigma = o.imu.gyro_bias_initial_sigma;
  setup.noise.baro_pressure_sigma_pa = o.baro.pressure_sigma_pa;
  // Clocks drawn as one are known to be one; a drawn delay is for the estimator to find (its prior).
  if (o.uwb.time_offset_s == 0.0) setup.uwb_clock.sigma_s = 0.0;
  return setup;
}

namespace {

/// The generator's choices, recorded only for scenarios other than the paper's (whose
/// truth.yaml stays as it always was).
void addScenarioScalars(const SimulationOptions& o, const Trajectory& trajectory, std::map<std::string, double>& sc) {
  if (o.isPaperScenario()) return;
  const Eigen::Vector3d hall = o.hall().size();
  sc["scenario_trajectory_kind"] = static_cast<double>(o.trajectory_kind);
  sc["scenario_anchor_layout"] = static_cast<double>(o.anchor_layout);
  sc["scenario_hall_x_m"] = hall.x();
  sc["scenario_hall_y_m"] = hall.y();
  sc["scenario_hall_z_m"] = hall.z();
  sc["scenario_n_tags"] = o.n_tags;
  sc["scenario_n_known_anchors"] = o.n_known_anchors;
  sc["scenario_n_unknown_anchors"] = o.n_unknown_anchors;
  sc["scenario_has_landed_phase"] = trajectory.hasLandedPhase() ? 1.0 : 0.0;
  sc["scenario_has_barometer"] = trajectory.hasBarometer() ? 1.0 : 0.0;
  sc["hardware_gamma_max_m"] = o.hardware.gamma_max_m;
}

/// truth.yaml: evaluation only.
Truth makeTruth(const SimulationOptions& o, const PaperScenario& scenario, const Trajectory& trajectory,
                const UwbHardwareBiases& biases, const RunFacts& f) {
  Truth truth;
  truth.anchor_positions = scenario.anchors_p_AinG;
  truth.pair_biases = biases.allTrue(o.uwb.sigma_range_m);
  auto& sc = truth.scalars;
  sc["seed"] = static_cast<double>(o.seed);
  sc["hardware_seed"] = static_cast<double>(o.hardware.hardware_seed);
  sc["duration_s"] = f.t_end_s;
  sc["duration_scale"] = o.duration_scale;
  sc["takeoff_time_s"] = trajectory.takeoffTime();
  sc["touchdown_time_s"] = trajectory.touchdownTime();
  sc["max_height_m"] = f.max_height_m;
  sc["sigma_range_m"] = o.uwb.sigma_range_m;
  sc["outlier_fraction"] = o.uwb.outlier_fraction;
  sc["drop_fraction"] = o.uwb.drop_fraction;
  if (o.uwb.time_offset_s != 0.0) sc["range_time_offset_s"] = o.uwb.time_offset_s;  // the stamps' delay
  sc["tdma_slot_s"] = o.uwb.slot_s;
  sc["tdma_t0_s"] = f.tdma_t0_s;
  sc["n_range_slots"] = static_cast<double>(f.uwb->slotCount());
  sc["n_ranges"] = static_cast<double>(f.n_ranges);
  sc["n_dropped"] = static_cast<double>(f.uwb->droppedCount());
  sc["n_outliers"] = static_cast<double>(f.uwb->outlierCount());
  sc["baro_reference_pressure_pa"] = f.baro.reference_pressure_pa;
  sc["baro_pressure_sigma_pa"] = f.baro.pressure_sigma_pa;
  const char* axes[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    sc[std::string("imu_acc_bias0_") + axes[i]] = f.imu->initialAccBias()[i];
    sc[std::string("imu_gyro_bias0_") + axes[i]] = f.imu->initialGyroBias()[i];
    sc[std::string("imu_acc_bias_end_") + axes[i]] = f.imu->finalAccBias()[i];
    sc[std::string("imu_gyro_bias_end_") + axes[i]] = f.imu->finalGyroBias()[i];
  }
  if (o.imu.scale_sigma > 0.0 || o.imu.misalignment_sigma_rad > 0.0)  // T = I + scale + misalignment
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const std::string ij = std::string(axes[i]) + axes[j];
        sc["imu_acc_axes_" + ij] = f.imu->accAxes()(i, j);
        sc["imu_gyro_axes_" + ij] = f.imu->gyroAxes()(i, j);
      }
  addScenarioScalars(o, trajectory, sc);
  return truth;
}

}  // namespace

SimulationResult ScenarioSimulator::run() const {
  const SimulationOptions& o = options_;
  SimulationResult result;
  const std::unique_ptr<Trajectory> trajectory_owner = makeTrajectory(o);
  const Trajectory& trajectory = *trajectory_owner;
  result.trajectory_kind = trajectory.kind();
  result.trajectory_description = trajectory.toString();
  result.has_landed_phase = trajectory.hasLandedPhase();
  result.takeoff_time_s = trajectory.takeoffTime();
  result.touchdown_time_s = trajectory.touchdownTime();
  const double t_end = trajectory.duration();
  Dataset& ds = result.dataset;
  RunFacts facts;
  facts.t_end_s = t_end;

  ImuSimulator imu(o.imu, o.seed);
  ds.imu = imu.simulate(trajectory, t_end);

  // Barometer (not on a hand-held rig) with a seeded reference pressure at z = 0.
  RandomStream rng_ref(RandomStream::deriveSeed(o.seed, "baro_reference"));
  facts.baro = o.baro;
  facts.baro.reference_pressure_pa =
      o.reference_pressure_mean_pa + rng_ref.uniform(-o.reference_pressure_spread_pa, o.reference_pressure_spread_pa);
  facts.baro.p_IP = scenario_.baro_p_IP;
  if (trajectory.hasBarometer()) ds.baro = BaroSimulator(facts.baro, o.seed).simulate(trajectory, t_end);

  // UWB: meshed TDMA over every device, fixed hardware biases, seeded noise/outliers/drops; seeded
  // TDMA phase (µs grid).
  RandomStream rng_tdma(RandomStream::deriveSeed(o.seed, "tdma_phase"));
  facts.tdma_t0_s = std::round(rng_tdma.uniform(0.0, o.uwb.slot_s) * 1e6) * 1e-6;
  const TdmaSchedule schedule(scenario_.uwbDeviceIds(), o.uwb.slot_s, facts.tdma_t0_s);
  const UwbHardwareBiases biases(scenario_.uwbDeviceIds(), o.hardware);
  UwbRangeSimulator uwb(scenario_, biases, o.uwb, o.seed);
  if (o.mesh_ranges) result.ranges = uwb.simulate(trajectory, schedule, t_end);
  ds.ranges.reserve(result.ranges.size());
  for (const auto& r : result.ranges) ds.ranges.push_back(r.sample);
  facts.n_ranges = ds.ranges.size();

  // Flight state (only for motions that rest on the ground) and ground truth.
  if (trajectory.hasLandedPhase()) {
    for (int64_t k = 0, n = sampleCount(o.flight_state_rate_hz, t_end); k < n; ++k) {
      const double t = static_cast<double>(k) / o.flight_state_rate_hz;
      ds.flight_states.push_back({Timestamp::fromSec(t), trajectory.isLanded(t)});
    }
  }
  facts.max_height_m = -1e9;
  for (int64_t k = 0, n = sampleCount(o.ground_truth_rate_hz, t_end); k < n; ++k) {
    const double t = static_cast<double>(k) / o.ground_truth_rate_hz;
    const TrajectoryState st = trajectory.evaluate(t);
    ds.ground_truth.push_back({Timestamp::fromSec(t), st.p_IinG, st.q_ItoG});
    facts.max_height_m = std::max(facts.max_height_m, st.p_IinG.z());
  }

  ds.setup = makeSetup(o, scenario_, trajectory, biases, facts.baro);
  facts.imu = &imu;
  facts.uwb = &uwb;
  ds.truth = makeTruth(o, scenario_, trajectory, biases, facts);

  result.stats.duration_s = t_end;
  result.stats.n_range_slots = uwb.slotCount();
  result.stats.n_dropped = uwb.droppedCount();
  result.stats.n_outliers = uwb.outlierCount();
  result.stats.max_height_m = facts.max_height_m;
  return result;
}

}  // namespace meshnav::sim
