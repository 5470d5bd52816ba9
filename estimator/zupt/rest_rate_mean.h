#pragma once
/// @file rest_rate_mean.h
/// @brief The mean gyro reading between two zero-velocity updates, for their ω = 0 rows.
///
/// At rest every gyro reading is ω_m,i = b_ω + n_i, the white noise of density σ_ω held over the
/// sample's interval Δt_i (variance σ_ω²/Δt_i). Weighting the readings by their intervals,
///   ω̄ = Σ ω_m,i Δt_i / T,  T = Σ Δt_i,  Var(ω̄ − b_ω) = σ_ω² / T,
/// so a 0.1 s ZUPT interval of a 200 Hz IMU measures b_ω √20 times better than its latest reading
/// alone. Using one reading (σ_ω √rate) with a fixed σ left most of the landed phase's gyro-bias
/// information unused; the yaw then drifts at the remaining gyro z-bias error in flight, where
/// the heading is only weakly observable (docs/results.md, "Yaw on seeds 8 and 11").
/// An interval longer than `max_dt_s` (an IMU gap) counts as `max_dt_s`: held readings carry no
/// new information.

#include <Eigen/Core>

namespace meshnav::estimator {

class RestRateMean {
 public:
  /// Adds a reading `gyro_rad_s` standing for the interval `dt_s` before it (clamped to
  /// [0, max_dt_s]).
  void add(const Eigen::Vector3d& gyro_rad_s, double dt_s, double max_dt_s) {
    const double dt = dt_s < 0.0 ? 0.0 : (dt_s > max_dt_s ? max_dt_s : dt_s);
    sum_ += gyro_rad_s * dt;
    span_s_ += dt;
  }
  void reset() {
    sum_.setZero();
    span_s_ = 0.0;
  }
  /// T = Σ Δt_i [s]; 0 before the first interval.
  double span() const { return span_s_; }
  /// ω̄ [rad/s]; only meaningful when span() > 0.
  Eigen::Vector3d mean() const { return span_s_ > 0.0 ? Eigen::Vector3d(sum_ / span_s_) : Eigen::Vector3d::Zero(); }
  /// σ of ω̄ − b_ω per axis for the noise density `gyro_noise_density` [rad/s/√Hz]: σ_ω/√T [rad/s].
  double sigma(double gyro_noise_density) const;

 private:
  Eigen::Vector3d sum_ = Eigen::Vector3d::Zero();  ///< Σ ω_m,i Δt_i [rad]
  double span_s_ = 0.0;
};

}  // namespace meshnav::estimator
