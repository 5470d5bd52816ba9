#include "sim/imu_simulator.h"

#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>


namespace meshnav::sim {

ImuNoiseOptions ImuNoiseOptions::noiseless() {
  ImuNoiseOptions o;
  o.acc_noise_density = o.gyro_noise_density = 0.0;
  o.acc_bias_rw = o.gyro_bias_rw = 0.0;
  o.acc_bias_initial_sigma = o.gyro_bias_initial_sigma = 0.0;
  o.vibration_acc_m_s2 = o.vibration_gyro_rad_s = 0.0;
  return o;
}

ImuNoiseOptions ImuNoiseOptions::forGrade(const std::string& grade) {
  struct Grade {
    const char* name;
    double acc_nd, gyro_nd, acc_rw, gyro_rw, acc_b0, gyro_b0;
  };
  // See the table in imu_simulator.h; "fc" equals the defaults.
  static constexpr std::array<Grade, 3> kGrades{{{"consumer", 6e-3, 6e-4, 1e-2, 1e-4, 0.1, 0.01},
                                                 {"fc", 2e-3, 2e-4, 3e-3, 2e-5, 0.05, 0.005},
                                                 {"tactical", 5e-4, 3e-5, 3e-4, 1e-6, 0.01, 0.0005}}};
  for (const Grade& g : kGrades) {
    if (grade != g.name) continue;
    ImuNoiseOptions o;
    o.acc_noise_density = g.acc_nd;
    o.gyro_noise_density = g.gyro_nd;
    o.acc_bias_rw = g.acc_rw;
    o.gyro_bias_rw = g.gyro_rw;
    o.acc_bias_initial_sigma = g.acc_b0;
    o.gyro_bias_initial_sigma = g.gyro_b0;
    return o;
  }
  throw std::invalid_argument("unknown IMU grade '" + grade + "' (consumer|fc|tactical)");
}

std::string ImuNoiseOptions::toString() const {
  std::ostringstream s;
  s << "imu: " << rate_hz << " Hz, acc noise " << acc_noise_density << " m/s^2/sqrt(Hz), gyro noise "
    << gyro_noise_density << " rad/s/sqrt(Hz), acc bias rw " << acc_bias_rw << " m/s^3/sqrt(Hz), gyro bias rw "
    << gyro_bias_rw << " rad/s^2/sqrt(Hz), initial bias sigma " << acc_bias_initial_sigma << " m/s^2, "
    << gyro_bias_initial_sigma << " rad/s";
  if (scale_sigma > 0.0 || misalignment_sigma_rad > 0.0)
    s << ", axis scale sigma " << scale_sigma << ", misalignment sigma " << misalignment_sigma_rad << " rad";
  if (vibration_acc_m_s2 > 0.0 || vibration_gyro_rad_s > 0.0)
    s << ", rotor vibration " << vibration_acc_m_s2 << " m/s^2, " << vibration_gyro_rad_s << " rad/s at "
      << rotor_min_hz << "-" << rotor_max_hz << " Hz while airborne";
  return s.str();
}

ImuSimulator::ImuSimulator(const ImuNoiseOptions& options, uint64_t seed) : options_(options), seed_(seed) {}

ImuSample ImuSimulator::ideal(const TrajectoryState& st) {
  ImuSample s;
  s.t = Timestamp::fromSec(st.t_s);
  const Eigen::Vector3d g_G(0.0, 0.0, -Trajectory::kGravity_m_s2);
  s.acc_m_s2 = st.R_ItoG.transpose() * (st.a_IinG - g_G);
  s.gyro_rad_s = st.w_IinI;
  return s;
}

void ImuSimulator::start(bool rotorcraft) {
  rng_noise_.emplace(RandomStream::deriveSeed(seed_, "imu_noise"));
  rng_bias_.emplace(RandomStream::deriveSeed(seed_, "imu_bias"));
  n_sampled_ = 0;
  bias_acc_ = rng_bias_->gaussian3(options_.acc_bias_initial_sigma);
  bias_gyro_ = rng_bias_->gaussian3(options_.gyro_bias_initial_sigma);
  bias_acc0_ = bias_acc_;
  bias_gyro0_ = bias_gyro_;
  // The axes from a stream of their own: exact axes leave every other draw as it was.
  acc_T_ = gyro_T_ = Eigen::Matrix3d::Identity();
  if (options_.scale_sigma > 0.0 || options_.misalignment_sigma_rad > 0.0) {
    RandomStream rng_axes(RandomStream::deriveSeed(seed_, "imu_axes"));
    for (Eigen::Matrix3d* T : {&acc_T_, &gyro_T_})
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          (*T)(i, j) += rng_axes.gaussian(i == j ? options_.scale_sigma : options_.misalignment_sigma_rad);
  }

  // Rotor vibration: tones, amplitudes and phases from a stream of their own.
  rotorcraft_ = rotorcraft && (options_.vibration_acc_m_s2 > 0.0 || options_.vibration_gyro_rad_s > 0.0);
  rotor_hz_ = {0.0, 0.0};
  phase_acc_.setZero();
  phase_gyro_.setZero();
  amp_acc_.setZero();
  amp_gyro_.setZero();
  if (rotorcraft_) {
    RandomStream rng_vib(RandomStream::deriveSeed(seed_, "imu_vibration"));
    for (double& f : rotor_hz_) f = rng_vib.uniform(options_.rotor_min_hz, options_.rotor_max_hz);
    for (int i = 0; i < 3; ++i) {
      amp_acc_(i) = rng_vib.uniform(0.5, 1.5) * options_.vibration_acc_m_s2;
      amp_gyro_(i) = rng_vib.uniform(0.5, 1.5) * options_.vibration_gyro_rad_s;
      for (int j = 0; j < 2; ++j) {
        phase_acc_(i, j) = rng_vib.uniform(0.0, 2.0 * M_PI);
        phase_gyro_(i, j) = rng_vib.uniform(0.0, 2.0 * M_PI);
      }
    }
  }
}

ImuSample ImuSimulator::sample(const TrajectoryState& state, bool airborne) {
  if (!rng_noise_) start(true);
  const double dt = 1.0 / options_.rate_hz;
  const double sigma_acc_d = options_.acc_noise_density / std::sqrt(dt);
  const double sigma_gyro_d = options_.gyro_noise_density / std::sqrt(dt);
  const double sigma_acc_w = options_.acc_bias_rw * std::sqrt(dt);
  const double sigma_gyro_w = options_.gyro_bias_rw * std::sqrt(dt);
  const auto vibration = [&](double t, const Eigen::Vector3d& amp, const Eigen::Matrix<double, 3, 2>& phase) {
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i)
      v(i) = amp(i) * (std::sin(2.0 * M_PI * rotor_hz_[0] * t + phase(i, 0)) +
                       std::sin(2.0 * M_PI * rotor_hz_[1] * t + phase(i, 1))) / std::sqrt(2.0);
    return v;
  };
  if (n_sampled_ > 0) {
    bias_acc_ += rng_bias_->gaussian3(sigma_acc_w);
    bias_gyro_ += rng_bias_->gaussian3(sigma_gyro_w);
  }
  ++n_sampled_;
  ImuSample s = ideal(state);
  s.acc_m_s2 = acc_T_ * s.acc_m_s2 + bias_acc_ + rng_noise_->gaussian3(sigma_acc_d);
  s.gyro_rad_s = gyro_T_ * s.gyro_rad_s + bias_gyro_ + rng_noise_->gaussian3(sigma_gyro_d);
  if (rotorcraft_ && airborne) {
    s.acc_m_s2 += vibration(state.t_s, amp_acc_, phase_acc_);
    s.gyro_rad_s += vibration(state.t_s, amp_gyro_, phase_gyro_);
  }
  return s;
}

std::vector<ImuSample> ImuSimulator::simulate(const Trajectory& trajectory, double t_end_s) {
  start(!trajectory.isHandCarried());
  const double dt = 1.0 / options_.rate_hz;
  std::vector<ImuSample> out;
  const auto n = static_cast<int64_t>(std::floor(t_end_s / dt + 1e-9)) + 1;
  out.reserve(static_cast<size_t>(n));
  for (int64_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * dt;
    out.push_back(sample(trajectory.evaluate(t), !trajectory.isLanded(t)));
  }
  return out;
}

}  // namespace meshnav::sim
