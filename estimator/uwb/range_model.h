#pragma once
/// @file range_model.h
/// @brief Range model (paper eq. UWB-meas-range): z = β_ab d_ab + γ_ab + ν, with
///   tag T on the IMU: p_TinG = p_IinG + R_ItoG p_TinI,  d = ‖p_A − p_TinG‖,
///   anchor–anchor:    d = ‖p_Ab − p_Aa‖.
/// A range stamped t (UWB clock) was measured at the IMU-clock instant t − δ_u (δ_u: the UWB
/// stamps' delay, a ClockOffsetKind state or setup's constant): the tag is taken where it was then,
/// to first order in δ_u, with ω̂ = ω − b_ω the measurement's body rate:
///   p_TinG = p_IinG − δ_u v_IinG + R_ItoG l,  l = p_TinI − δ_u [ω̂]× p_TinI.
/// Jacobians with u = (p_far − p_near)/d (unit vector from the tag / first anchor):
///   ∂z/∂δp_IinG = −β uᵀ,  ∂z/∂δv = β δ_u uᵀ,  ∂z/∂δθ = β uᵀ R̂ [l]×,  ∂z/∂δb_ω = β δ_u uᵀ R̂ [p_TinI]×,
///   ∂z/∂δδ_u = β uᵀ v_T with v_T = v_IinG + R̂ (ω̂ × p_TinI),  ∂z/∂δp_A = β uᵀ (estimated anchor),
///   anchor–anchor: ∂z/∂δp_Aa = −β uᵀ, ∂z/∂δp_Ab = β uᵀ.
/// Noise variance R = σ² + σ_γ² + (d σ_β)² (pair uncertainties inflate the noise), except when γ
/// of the pair is a state — of an estimated anchor at one end (its calibration's γ towards tags,
/// known and earlier calibrated anchors, rows 3.. of the anchor's block; looked up first) or of
/// a tag instance (γ towards exactly known anchors): then ∂z/∂δγ = 1 and σ_γ is not added.
/// β stays a fixed value (its σ_β inflates R).

#include <Eigen/Core>

#include "estimator/core/linearization.h"
#include "estimator/core/nominal_state.h"
#include "estimator/uwb/range_measurement.h"
#include "estimator/uwb/uwb_network.h"

namespace meshnav::estimator {

class RangeModel {
 public:
  enum class Status {
    Ok,
    UnknownId,    ///< an end is neither a tag nor a known/estimated anchor
    NoState,      ///< both ends exactly known anchors: nothing to estimate
    TagTag,       ///< both ends on the vehicle: constant distance, no information
    Degenerate,   ///< predicted distance ~0
  };
  /// Predicted range β d + γ and the distance d, when both ends are known.
  static std::optional<std::pair<double, double>> predict(const RangeMeasurement& z, const NominalState& x,
                                                          const UwbNetwork& net);
  /// Whether the range can be fused (cheap: no distance computed; Degenerate is not detected).
  static Status classify(const RangeMeasurement& z, const NominalState& x, const UwbNetwork& net);
  /// Linearizes into `out` (blocks per instance with state) when Status::Ok.
  static Status linearize(const RangeMeasurement& z, const NominalState& x, const UwbNetwork& net,
                          Linearization* out);
  static const char* statusName(Status s);
};

}  // namespace meshnav::estimator
