#pragma once
/// @file range_error_correlation.h
/// @brief Time-correlated range errors (issue 34; derivation in docs/uwb_bias_model.md,
/// "Correlated errors"): the R inflation of a range from the time since its pair's previous one.
///
/// A pair's range error, its constant γ removed, is modelled as a first-order Gauss–Markov
/// process with correlation time τ: e_k = ρ e_{k−1} + w_k, ρ = exp(−Δt/τ), Δt the time since the
/// pair's previous range, Var e = σ². The filter fuses each range as if its error were white. n
/// such ranges carry the information of n (1 − ρ)/(1 + ρ) independent ones (the variance of their
/// mean is σ²/n · (1 + ρ)/(1 − ρ) for n ≫ 1), so each is fused with
///
///     R_eff = R · (1 + ρ)/(1 − ρ).
///
/// Ranges of a pair further apart than a few τ are unchanged (ρ → 0); repeated ones at the same
/// instant carry almost nothing (Δt is floored at kMinDt_s). The first range of a pair, and every
/// range when τ = 0, keeps R. The previous range counts whether it was fused or gated: the error
/// process went on through it, and a gated range is an excursion the next one shares with
/// correlation ρ (counting only fused ones shrank the next range's gate after each refusal: ISAS-Walk1
/// gated 30 ranges instead of 6, 0.267 m instead of 0.255 m). Part of FilterContext, so a rewind
/// restores it with the filter.

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "common/time.h"
#include "common/types.h"

namespace meshnav::estimator {

class RangeErrorCorrelation {
 public:
  static constexpr double kMinDt_s = 1e-3;  ///< floor of Δt (ρ ≤ exp(−kMinDt_s/τ)) [s]

  RangeErrorCorrelation() = default;
  /// `tau_s`: correlation time τ [s] (0: white errors, no inflation).
  explicit RangeErrorCorrelation(double tau_s) : tau_s_(tau_s) {}

  /// (1 + ρ)/(1 − ρ) for a range of pair (a, b) at `t` (1 with no earlier range of the pair, when
  /// τ = 0, or for a range older than the pair's newest one).
  double inflation(SensorId a, SensorId b, Timestamp t) const {
    if (tau_s_ <= 0.0) return 1.0;
    auto it = last_fused_.find(pairKey(a, b));
    if (it == last_fused_.end() || t < it->second) return 1.0;
    const double rho = std::exp(-std::max((t - it->second).sec(), kMinDt_s) / tau_s_);
    return (1.0 + rho) / (1.0 - rho);
  }
  /// A range of (a, b) at `t` went through the update (fused or gated).
  void noteRange(SensorId a, SensorId b, Timestamp t) {
    if (tau_s_ <= 0.0) return;  // white errors: no history to keep
    auto [it, inserted] = last_fused_.try_emplace(pairKey(a, b), t);
    if (!inserted) it->second = std::max(it->second, t);
  }
  double tau_s() const { return tau_s_; }

 private:
  double tau_s_ = 0.0;
  std::map<std::pair<SensorId, SensorId>, Timestamp> last_fused_;
};

}  // namespace meshnav::estimator
