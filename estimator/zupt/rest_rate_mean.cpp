#include "estimator/zupt/rest_rate_mean.h"

#include <cmath>
#include <limits>

namespace meshnav::estimator {

double RestRateMean::sigma(double gyro_noise_density) const {
  if (span_s_ <= 0.0) return std::numeric_limits<double>::infinity();
  return gyro_noise_density / std::sqrt(span_s_);
}

}  // namespace meshnav::estimator
