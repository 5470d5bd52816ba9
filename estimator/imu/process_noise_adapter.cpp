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

bool ProcessNoiseAdapter::onRangeNis(double nis, double prior_ratio, bool accepted) {
  if (!options_.enabled || !std::isfinite(nis) || nis < 0.0) return false;
  batch_.push_back(nis);
  accepted_.push_back(accepted);
  prior_ratios_.push_back(std::isfinite(prior_ratio) ? prior_ratio : 0.0);
  if (static_cast<int>(batch_.size()) < options_.batch) return false;
  std::vector<double> accepted_nis;
  for (std::size_t i = 0; i < batch_.size(); ++i)
    if (accepted_[i]) accepted_nis.push_back(batch_[i]);
  const bool mostly_accepted = !accepted_nis.empty() && static_cast<double>(accepted_nis.size()) >=
                                                           options_.min_accepted_fraction * static_cast<double>(batch_.size());
  const double r = median(mostly_accepted ? accepted_nis : batch_) / kConsistentMedianNis;
  const double prior = median(prior_ratios_);
  batch_.clear();
  accepted_.clear();
  prior_ratios_.clear();
  last_ratio_ = r;
  ++decisions_;
  const bool above = r > options_.upper_ratio && prior <= options_.max_prior_ratio;  // else Q is not the cause
  if (!above) recent_above_.clear();
  if (!above && r >= options_.lower_ratio) return false;
  double evidence = r;  // a shrink: this batch alone
  if (above) {
    recent_above_.push_back(r);
    if (static_cast<int>(recent_above_.size()) > options_.confirm_batches) recent_above_.erase(recent_above_.begin());
    const bool confirmed = static_cast<int>(recent_above_.size()) >= options_.confirm_batches;
    const bool at_once = r > options_.grow_at_once_ratio;
    if (!confirmed && !at_once) return false;
    // Grow by the smallest ratio of the confirming run, or by this batch's own when far enough above.
    evidence = std::max(confirmed ? *std::min_element(recent_above_.begin(), recent_above_.end()) : 0.0,
                        at_once ? r : 0.0);
  }
  const double step = std::clamp(evidence, 1.0 / options_.max_shrink, options_.max_grow);
  const double next = std::clamp(scale_ * step, 1.0, options_.max_scale);
  if (next == scale_) return false;
  scale_ = next;
  return true;
}

}  // namespace meshnav::estimator
