/// @file input_gate.cpp
/// @brief InputGate: value checks, the time guard and duplicates (input_gate.h).

#include "estimator/node/input_gate.h"

#include <cmath>

#include "common/anchor_init_io.h"
#include "common/plausibility.h"
#include "estimator/node/node_internals.h"

namespace meshnav::estimator {

using node_internal::where;

namespace {

Timestamp& stamp(EstimatorInput& in) {
  return std::visit([](auto& m) -> Timestamp& { return m.t; }, in);
}

/// Why `in` holds a value no sensor gives, or "" when it does not.
std::string badValue(const EstimatorInput& in, const UwbOptions& uwb) {
  const Timestamp t = inputTime(in);
  if (const auto* s = std::get_if<ImuSample>(&in)) {
    if (!s->acc_m_s2.allFinite() || !s->gyro_rad_s.allFinite() ||
        s->acc_m_s2.norm() > plausible::kMaxSpecificForce_m_s2 || s->gyro_rad_s.norm() > plausible::kMaxAngularRate_rad_s)
      return where("IMU", t) + ": non-finite or absurd reading";
  } else if (const auto* s = std::get_if<BaroSample>(&in)) {
    if (!std::isfinite(s->pressure_pa) || s->pressure_pa < plausible::kMinPressure_pa ||
        s->pressure_pa > plausible::kMaxPressure_pa)
      return where("BARO", t) + ": non-finite or absurd pressure " + std::to_string(s->pressure_pa);
  } else if (const auto* s = std::get_if<HeightSample>(&in)) {
    if (!std::isfinite(s->range_m) || s->range_m < 0.0 || s->range_m > plausible::kMaxHeight_m)
      return where("HEIGHT", t) + ": non-finite or absurd range to the floor " + std::to_string(s->range_m);
  } else if (const auto* s = std::get_if<RangeSample>(&in)) {
    const double z = uwb.use_corrected_range ? s->range_corr_m : s->range_m;
    if (!std::isfinite(z) || z < -0.5 || z > uwb.max_range_m || !std::isfinite(s->R_m2) || s->R_m2 < 0)
      return where("RANGE", t) + ": bad range " + std::to_string(z) + " m between " + std::to_string(s->id_initiator) +
             " and " + std::to_string(s->id_responder);
    if (uwb.use_corrected_range && std::abs(s->range_corr_m - s->range_m) > InputGate::kMaxRangeCorrection_m)
      return where("RANGE", t) + ": corrected range " + std::to_string(s->range_corr_m) + " m is more than " +
             std::to_string(InputGate::kMaxRangeCorrection_m) + " m from the raw " + std::to_string(s->range_m) +
             " m (not given? old logs carry 0)";
    if (s->id_initiator == s->id_responder || s->id_initiator <= 0 || s->id_responder <= 0)
      return where("RANGE", t) + ": invalid ids " + std::to_string(s->id_initiator) + ", " +
             std::to_string(s->id_responder);
  } else if (const auto* pr = std::get_if<PeerRange>(&in)) {
    if (const std::string e = badValue(EstimatorInput(pr->range), uwb); !e.empty()) return "PEER_" + e;
    const Eigen::Matrix3d& S = pr->cov_peer_tag_m2;
    if (!pr->p_peer_tag_in_G.allFinite() || !S.allFinite() || (S.diagonal().array() < 0.0).any() ||
        !S.isApprox(S.transpose(), 1e-9) || pr->range.t != pr->t)
      return where("PEER_RANGE", t) + ": the peer tag " + std::to_string(pr->peer_tag) +
             "'s position or covariance is not finite, not symmetric or negative, or its range is stamped elsewhere";
  } else if (const auto* a = std::get_if<AnchorInit>(&in)) {
    if (const std::string e = anchorInitValueError(*a); !e.empty()) return where("ANCHOR_INIT", t) + ": " + e;
  } else if (const auto* c = std::get_if<EstimatorCommand>(&in);
             c && c->action == EstimatorCommand::Action::AddAnchor) {
    if (const std::string e = anchorInitValueError(c->anchorToAdd()); !e.empty())
      return where("ESTIMATOR_CMD", t) + ": " + e;
  }
  return "";
}

}  // namespace

InputGate::InputGate(const EstimatorOptions& options, Diagnostics& diag)
    : options_(options), diag_(diag), time_guard_(options.time) {}

bool InputGate::valid(const EstimatorInput& in) {
  const std::string bad = badValue(in, options_.uwb);
  if (bad.empty()) return true;
  diag_.report("bad_input", bad);
  return false;
}

InputGate::Verdict InputGate::admitTime(EstimatorInput& in) {
  const std::string kind = inputKindName(in);
  Timestamp& t = stamp(in);
  const Duration max_offset = Duration::fromSec(options_.time.max_offset_s);
  // Commands are not measurements and do not drive the clock: far from it, they apply now.
  if (std::holds_alternative<AnchorInit>(in) || std::holds_alternative<EstimatorCommand>(in)) {
    if (const auto now = time_guard_.now(); now && (t > *now + max_offset || t < *now - max_offset)) {
      diag_.report(kind + ":time_clamped", kind + " stamped t=" + formatSeconds(t) + " is more than " +
                                               std::to_string(options_.time.max_offset_s) +
                                               " s from the current time " + formatSeconds(*now) + "; applied now");
      t = *now;
    }
    return Verdict::kAdmitted;
  }
  const TimeGuard::Verdict v = time_guard_.admit(kind, t, diag_);
  if (v == TimeGuard::Verdict::Ahead || v == TimeGuard::Verdict::Behind) return Verdict::kRefused;
  if (v == TimeGuard::Verdict::Rebased && time_guard_.lastJump().us < 0) return Verdict::kClockBack;
  return Verdict::kAdmitted;
}

bool InputGate::admitOnce(const EstimatorInput& in, const std::optional<Timestamp>& newest) {
  const InputOrder key = inputOrder(in);
  if (newest) {
    // Keys older than the window are forgotten: such an input is refused as too old anyway.
    const int64_t oldest = (*newest - Duration::fromSec(options_.window_s)).us;
    while (!seen_.empty() && seen_.begin()->t_us < oldest) seen_.erase(seen_.begin());
  }
  if (!seen_.insert(key).second) {
    const std::string kind = inputKindName(in);
    diag_.report(kind + ":duplicate", kind + " at t=" + formatSeconds(inputTime(in)) +
                                          " came a second time (same time and ids); dropped");
    return false;
  }
  return true;
}

}  // namespace meshnav::estimator
