#pragma once
/// @file loop_jitter.h
/// @brief The timing of a control loop driven by messages (the `controller` process): for
/// consecutive updates k−1, k at data times t and wall times w,
///   j_k = | (w_k − w_{k−1}) − (t_k − t_{k−1}) |,
/// how much the wall interval between two updates differs from the data interval they cover
/// (0 for a loop that runs exactly on the data clock). Meaningful when the data runs at wall speed
/// (vehicle_sim --realtime); in lock-step the data clock runs faster than the wall.
/// p99 and max over every update so far (the values are kept: 200 Hz × a 150 s flight is 30 000).

#include <cstdint>
#include <optional>
#include <vector>

namespace meshnav::controller {

class LoopJitter {
 public:
  /// One update at data time `data_us` and wall time `wall_us` [µs]. A data time that does not
  /// advance is not counted.
  void add(int64_t data_us, int64_t wall_us);
  /// Number of intervals measured.
  size_t count() const { return jitter_us_.size(); }
  /// q-quantile (0..1) of j [ms] (nearest rank); −1 without an interval.
  double quantileMs(double q) const;
  double maxMs() const;

 private:
  std::optional<int64_t> last_data_us_, last_wall_us_;
  std::vector<int64_t> jitter_us_;
};

}  // namespace meshnav::controller
