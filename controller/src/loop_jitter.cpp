#include "controller/loop_jitter.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace meshnav::controller {

void LoopJitter::add(int64_t data_us, int64_t wall_us) {
  if (last_data_us_ && data_us <= *last_data_us_) return;
  if (last_data_us_) jitter_us_.push_back(std::llabs((wall_us - *last_wall_us_) - (data_us - *last_data_us_)));
  last_data_us_ = data_us;
  last_wall_us_ = wall_us;
}

double LoopJitter::quantileMs(double q) const {
  if (jitter_us_.empty()) return -1.0;
  std::vector<int64_t> v = jitter_us_;
  const size_t rank = static_cast<size_t>(std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size())));
  const size_t i = rank == 0 ? 0 : rank - 1;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(i), v.end());
  return static_cast<double>(v[i]) / 1000.0;
}

double LoopJitter::maxMs() const {
  if (jitter_us_.empty()) return -1.0;
  return static_cast<double>(*std::max_element(jitter_us_.begin(), jitter_us_.end())) / 1000.0;
}

}  // namespace meshnav::controller
