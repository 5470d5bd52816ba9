#pragma once
/// @file health_monitor.h
/// @brief Filter health from windowed innovation statistics (docs/robustness.md).
///
/// Every update outcome (type, the anchor involved, accepted, NIS) enters a sliding window of
/// `window_s`. Per measurement type the monitor keeps the gated fraction and the mean NIS of the
/// accepted updates (E[NIS] = 1 for a consistent scalar update); per anchor the gated fraction.
/// - `lost` when, with at least `min_ranges` ranges in the window, the gated fraction reaches
///   `lost_gated_fraction` on at least `min_anchors` anchors; or the position σ exceeds
///   `lost_sigma_p_m`; or no range was accepted for `lost_no_aiding_s` (no usable aiding).
/// - `degraded` when the gated fraction reaches `degraded_gated_fraction`, the mean range NIS
///   exceeds `degraded_mean_nis`, or no range was accepted for `degraded_no_aiding_s`.
/// - `ok` otherwise. A state is reported after it held for `hold_s` (no flicker), except `lost`.

#include <deque>
#include <map>
#include <string>

#include "common/types.h"

namespace meshnav::estimator {

enum class Health { Initializing, Ok, Degraded, Lost };
const char* healthName(Health h);

struct HealthOptions {
  double window_s = 4.0;                 ///< statistics window [s]
  int min_ranges = 12;                   ///< ranges in the window before gating can mean `lost`
  int min_anchors = 2;                   ///< anchors gated alike before it means `lost`
  double degraded_gated_fraction = 0.3;  ///< [-]
  double lost_gated_fraction = 0.7;      ///< [-]
  double degraded_mean_nis = 4.0;        ///< mean NIS of accepted ranges (1 if consistent) [-]
  double degraded_no_aiding_s = 2.0;     ///< no accepted range for this long: degraded [s]
  double lost_no_aiding_s = 10.0;        ///< no accepted range for this long: lost [s]
  double lost_sigma_p_m = 3.0;           ///< largest position σ beyond which the pose is lost [m]
  double hold_s = 1.0;                   ///< a better state must hold this long to be reported [s]
};

/// Windowed statistics of one measurement type or one anchor.
struct HealthStats {
  int n = 0;
  int n_gated = 0;
  double nis_sum = 0.0;  ///< over accepted updates
  double gatedFraction() const { return n ? static_cast<double>(n_gated) / n : 0.0; }
  double meanNis() const { return n - n_gated > 0 ? nis_sum / (n - n_gated) : 0.0; }
};

class HealthMonitor {
 public:
  explicit HealthMonitor(const HealthOptions& options = {});

  /// One update outcome. `type` is "range" or "baro"; `anchor` 0 when none.
  void onUpdate(Timestamp t, const std::string& type, SensorId anchor, bool accepted, double nis);
  /// Re-evaluates at time t with the current largest position σ; returns true on a change.
  bool evaluate(Timestamp t, double sigma_p_max_m);
  /// Whether at least `min_ranges` accepted ranges in the window fit (mean NIS ≤ `degraded_mean_nis`) and one was
  /// accepted within `degraded_no_aiding_s`: a `degraded` state then comes from gating alone,
  /// which NLOS outliers cause as well as a drifting filter.
  bool acceptedRangesFit(Timestamp t) const;
  /// Forgets the window (after a re-initialization); the state becomes `ok` at `t`.
  void reset(Timestamp t);

  Health health() const { return health_; }
  const std::string& reason() const { return reason_; }
  /// Windowed statistics per type ("range", "baro") and per anchor ("anchor 101").
  std::map<std::string, HealthStats> stats() const;

 private:
  struct Event {
    Timestamp t;
    std::string type;
    SensorId anchor;
    bool accepted;
    double nis;
  };
  /// Adds (+1) or removes (−1) an event from the running statistics.
  void account(const Event& e, int sign);
  Health assess(Timestamp t, double sigma_p_max_m, std::string* why) const;
  /// The window's tag-range statistics (empty before the first).
  HealthStats rangeStats() const;

  HealthOptions options_;
  std::deque<Event> events_;
  std::map<std::string, HealthStats> by_type_;   ///< running, over `events_`
  std::map<SensorId, HealthStats> by_anchor_;    ///< running, over `events_`
  Health health_ = Health::Ok;
  std::string reason_;
  Timestamp last_accepted_range_;
  Health candidate_ = Health::Ok;
  Timestamp candidate_since_;
};

}  // namespace meshnav::estimator
