#pragma once
/// @file position_controller.h
/// @brief Cascaded position → velocity → attitude/thrust → body-rate controller on the ESTIMATED
/// pose (never the truth; docs/closed_loop.md).
///
/// With the estimate p̂, v̂, R̂ = R_ItoG and a setpoint (p_r, v_r, a_r, ψ_r):
///   v_c = v_r + K_p (p_r − p̂)                       (per axis; z: v_r,z only when !hold_z), clamped
///   e_v = v_c − v̂,  I ← I + K_i e_v Δt (clamped),  a_c = a_r + K_v e_v + I,  |a_c,xy| limited
///   f = a_c + g e_z, its horizontal part limited to the tilt  |f_xy| ≤ f_z tan θ_max
///   b₃ = f/‖f‖,  b₂ = b₃ × [cos ψ_r, sin ψ_r, 0] normalized,  b₁ = b₂ × b₃,  R_d = [b₁ b₂ b₃]
///   T_c = f · R̂ e_z   (collective thrust along the body z actually pointing)
///   e_R = ½ (R_dᵀ R̂ − R̂ᵀ R_d)^∨,  ω_c = −diag(k_tilt, k_tilt, k_yaw) e_R  (clamped)
/// The integral I absorbs drag, wind and the thrust's scale; `hoverThrust()` = g + I_z.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "controller/controller_options.h"
#include "controller/setpoint.h"

namespace meshnav::controller {

class PositionController {
 public:
  explicit PositionController(const ControllerOptions& options);

  /// One control step of `dt_s` [s] (integrates the velocity error) for the estimate
  /// (p̂, v̂, R̂) and the setpoint.
  ControlCommand compute(const Eigen::Vector3d& p_IinG, const Eigen::Vector3d& v_IinG,
                         const Eigen::Matrix3d& R_ItoG, const Setpoint& sp, double dt_s);
  /// Level attitude at heading `yaw_rad` and a thrust `descent_acc` below the hover thrust:
  /// the failsafe's descent (R̂: a fresh POSE's attitude, or one carried on with the commanded rates).
  ControlCommand levelDescent(const Eigen::Matrix3d& R_ItoG, double yaw_rad, double descent_acc_m_s2) const;
  /// Mass-normalized hover thrust as learnt by the integral, g + I_z [m/s²].
  double hoverThrust() const;
  /// Clears the integral (on the pad before a take-off).
  void reset();
  const Eigen::Vector3d& integral() const { return integral_; }

 private:
  /// ω_c for the desired attitude.
  Eigen::Vector3d attitudeRates(const Eigen::Matrix3d& R, const Eigen::Matrix3d& R_d) const;
  double clampThrust(double t) const;

  ControllerOptions options_;
  Eigen::Vector3d integral_ = Eigen::Vector3d::Zero();
};

}  // namespace meshnav::controller
