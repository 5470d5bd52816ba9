#include "estimator/imu/process_noise_adapter.h"

#include <algorithm>
#include <cmath>

namespace meshnav::estimator {

namespace {
/// Median of χ²(1): the median NIS of a consistent scalar update.
constexpr double kConsistentMedianNis = 0.4549364231195724;
}  // namespace

namespace {
double median(std::vector<double>& v) {
  auto mid = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}
}  // namespace

bool ProcessNoiseAdapter::onRangeNis(double nis, double prior_ratio, bool /*accepted*/) {
  if (!options_.enabled || !std::isfinite(nis) || nis < 0.0) return false;
  batch_.push_back(nis);
  prior_ratios_.push_back(std::isfinite(prior_ratio) ? prior_ratio : 0.0);
  if (static_cast<int>(batch_.size()) < options_.batch) return false;
  const double r = median(batch_) / kConsistentMedianNis;
  const double prior = median(prior_ratios_);
  batch_.clear();
  prior_ratios_.clear();
  last_ratio_ = r;
  ++decisions_;
  const bool above = r > options_.upper_ratio && prior <= options_.max_prior_ratio;  // else Q is not the cause
  if (!above && r >= options_.lower_ratio) return false;
  const double step = std::clamp(r, 1.0 / options_.max_shrink, options_.max_grow);
  const double next = std::clamp(scale_ * step, 1.0, options_.max_scale);
  if (next == scale_) return false;
  scale_ = next;
  return true;
}

}  // namespace meshnav::estimator
