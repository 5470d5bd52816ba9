#include "sim/scenario_simulator.h"

#include <cmath>
#include <numbers>

#include "sim/baro_simulator.h"
#include "sim/imu_simulator.h"
#include "sim/random_stream.h"
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

ScenarioSimulator::ScenarioSimulator(SimulationOptions options, PaperScenario scenario)
    : options_(std::move(options)), scenario_(std::move(scenario)) {
  options_.validate();
}

SimulationResult ScenarioSimulator::run() const {
  const SimulationOptions& o = options_;
  SimulationResult result;
  result.trajectory = o.trajectory ? *o.trajectory : TrajectoryOptions::randomized(o.seed, o.duration_scale);
  const SpiralTrajectory trajectory(result.trajectory);
  const double t_end = trajectory.duration();
  Dataset& ds = result.dataset;

  // IMU.
  ImuSimulator imu(o.imu, o.seed);
  ds.imu = imu.simulate(trajectory, t_end);

  // Barometer with a seeded reference pressure at z = 0.
  RandomStream rng_ref(RandomStream::deriveSeed(o.seed, "baro_reference"));
  BaroOptions baro_options = o.baro;
  baro_options.reference_pressure_pa =
      o.reference_pressure_mean_pa + rng_ref.uniform(-o.reference_pressure_spread_pa, o.reference_pressure_spread_pa);
  baro_options.p_IP = scenario_.baro_p_IP;
  ds.baro = BaroSimulator(baro_options, o.seed).simulate(trajectory, t_end);

  // UWB: meshed TDMA, fixed hardware biases, seeded noise/outliers/drops; seeded TDMA phase (µs grid).
  RandomStream rng_tdma(RandomStream::deriveSeed(o.seed, "tdma_phase"));
  const double tdma_t0 = std::round(rng_tdma.uniform(0.0, o.uwb.slot_s) * 1e6) * 1e-6;
  const TdmaSchedule schedule(scenario_.uwbDeviceIds(), o.uwb.slot_s, tdma_t0);
  const UwbHardwareBiases biases(scenario_.uwbDeviceIds(), o.hardware);
  UwbRangeSimulator uwb(scenario_, biases, o.uwb, o.seed);
  result.ranges = uwb.simulate(trajectory, schedule, t_end);
  ds.ranges.reserve(result.ranges.size());
  for (const auto& r : result.ranges) ds.ranges.push_back(r.sample);

  // Flight state and ground truth.
  for (int64_t k = 0, n = sampleCount(o.flight_state_rate_hz, t_end); k < n; ++k) {
    const double t = static_cast<double>(k) / o.flight_state_rate_hz;
    ds.flight_states.push_back({Timestamp::fromSec(t), trajectory.isLanded(t)});
  }
  double max_height = -1e9;
  for (int64_t k = 0, n = sampleCount(o.ground_truth_rate_hz, t_end); k < n; ++k) {
    const double t = static_cast<double>(k) / o.ground_truth_rate_hz;
    const TrajectoryState st = trajectory.evaluate(t);
    ds.ground_truth.push_back({Timestamp::fromSec(t), st.p_IinG, st.q_ItoG});
    max_height = std::max(max_height, st.p_IinG.z());
  }

  // setup.yaml: what a user knows.
  SystemSetup& setup = ds.setup;
  setup.imu_id = scenario_.imu_id;
  setup.baro_id = scenario_.baro_id;
  setup.rel_tag_positions = scenario_.tags_p_TinI;
  for (SensorId id : scenario_.known_anchor_ids) setup.abs_anchor_positions[id] = scenario_.anchors_p_AinG.at(id);
  std::vector<SensorId> calibrated_ids;
  for (const auto& [id, p] : scenario_.tags_p_TinI) calibrated_ids.push_back(id);
  for (SensorId id : scenario_.known_anchor_ids) calibrated_ids.push_back(id);
  std::sort(calibrated_ids.begin(), calibrated_ids.end());
  for (size_t i = 0; i < calibrated_ids.size(); ++i)
    for (size_t j = i + 1; j < calibrated_ids.size(); ++j)
      setup.pair_biases.push_back(biases.calibrated(calibrated_ids[i], calibrated_ids[j], o.uwb.sigma_range_m));
  setup.baro_p_IP = scenario_.baro_p_IP;
  setup.baro_reference_pressure_pa.reset();  // taken on the ground at start
  if (o.with_initial_pose) {
    RandomStream rng_pose(RandomStream::deriveSeed(o.seed, "initial_pose"));
    const TrajectoryState st0 = trajectory.evaluate(0.0);
    InitialPose pose;
    pose.p_IinG = st0.p_IinG + rng_pose.gaussian3(o.initial_pose_sigma_p_m);
    pose.yaw_deg = yawOf(st0.R_ItoG) * kRadToDeg + rng_pose.gaussian(o.initial_pose_sigma_yaw_deg);
    pose.sigma_p_m = o.initial_pose_sigma_p_m;
    pose.sigma_yaw_deg = o.initial_pose_sigma_yaw_deg;
    setup.initial_pose = pose;
  }
  setup.noise.sigma_range_m = o.uwb.sigma_range_m;
  setup.noise.imu_acc_noise_density = o.imu.acc_noise_density;
  setup.noise.imu_gyro_noise_density = o.imu.gyro_noise_density;
  setup.noise.imu_acc_bias_rw = o.imu.acc_bias_rw;
  setup.noise.imu_gyro_bias_rw = o.imu.gyro_bias_rw;
  setup.noise.baro_pressure_sigma_pa = o.baro.pressure_sigma_pa;

  // truth.yaml: evaluation only.
  Truth truth;
  truth.anchor_positions = scenario_.anchors_p_AinG;
  truth.pair_biases = biases.allTrue(o.uwb.sigma_range_m);
  auto& sc = truth.scalars;
  sc["seed"] = static_cast<double>(o.seed);
  sc["hardware_seed"] = static_cast<double>(o.hardware.hardware_seed);
  sc["duration_s"] = t_end;
  sc["duration_scale"] = o.duration_scale;
  sc["takeoff_time_s"] = trajectory.takeoffTime();
  sc["touchdown_time_s"] = trajectory.touchdownTime();
  sc["max_height_m"] = max_height;
  sc["sigma_range_m"] = o.uwb.sigma_range_m;
  sc["outlier_fraction"] = o.uwb.outlier_fraction;
  sc["drop_fraction"] = o.uwb.drop_fraction;
  sc["tdma_slot_s"] = o.uwb.slot_s;
  sc["tdma_t0_s"] = tdma_t0;
  sc["n_range_slots"] = static_cast<double>(uwb.slotCount());
  sc["n_ranges"] = static_cast<double>(ds.ranges.size());
  sc["n_dropped"] = static_cast<double>(uwb.droppedCount());
  sc["n_outliers"] = static_cast<double>(uwb.outlierCount());
  sc["baro_reference_pressure_pa"] = baro_options.reference_pressure_pa;
  sc["baro_pressure_sigma_pa"] = baro_options.pressure_sigma_pa;
  const char* axes[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    sc[std::string("imu_acc_bias0_") + axes[i]] = imu.initialAccBias()[i];
    sc[std::string("imu_gyro_bias0_") + axes[i]] = imu.initialGyroBias()[i];
    sc[std::string("imu_acc_bias_end_") + axes[i]] = imu.finalAccBias()[i];
    sc[std::string("imu_gyro_bias_end_") + axes[i]] = imu.finalGyroBias()[i];
  }
  ds.truth = truth;

  result.stats.duration_s = t_end;
  result.stats.n_range_slots = uwb.slotCount();
  result.stats.n_dropped = uwb.droppedCount();
  result.stats.n_outliers = uwb.outlierCount();
  result.stats.max_height_m = max_height;
  return result;
}

}  // namespace meshnav::sim
