/// @file estimator_node_time.cpp
/// @brief EstimatorNode: the time guard on every input (common/time_guard.h). An input stamped far
/// from the node's current time is refused and counted per kind before it can reach the
/// out-of-sequence history or the filter, so it never moves the filter's clock.
#include <spdlog/spdlog.h>

#include "estimator/node/estimator_node.h"

namespace meshnav::estimator {

namespace {

Timestamp& stamp(EstimatorInput& in) {
  return std::visit([](auto& m) -> Timestamp& { return m.t; }, in);
}

}  // namespace

bool EstimatorNode::admitTime(EstimatorInput& in) {
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
    return true;
  }
  const TimeGuard::Verdict v = time_guard_.admit(kind, t, diag_);
  if (v == TimeGuard::Verdict::Ahead || v == TimeGuard::Verdict::Behind) return false;
  if (v == TimeGuard::Verdict::Rebased && time_guard_.lastJump().us < 0) {
    spdlog::warn("estimator: the clock was ahead of every input; the node starts over");
    // Everything the node holds is stamped ahead of the data: nothing could ever be processed.
    resetAll();
    newest_.reset();
    next_anchor_pub_.reset();
    next_status_pub_.reset();
    last_health_eval_.reset();
    still_at_.clear();
    still_detector_ = StillnessDetector(StillnessOptions{}, options_.imu.acc_noise_density,
                                        options_.imu.gyro_noise_density, options_.gravity_m_s2);
    have_flight_state_ = false;
    last_pressure_pa_.reset();
  }
  return true;
}

bool EstimatorNode::admitOnce(const EstimatorInput& in) {
  const InputOrder key = inputOrder(in);
  if (newest_) {
    // Keys older than the window are forgotten: such an input is refused as too old anyway.
    const int64_t oldest = (*newest_ - Duration::fromSec(options_.window_s)).us;
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
