#include "estimator/node/step_timings.h"

#include <algorithm>

namespace meshnav::estimator {

void StepTimings::add(const std::string& type, double us) {
  Acc& a = acc_[type];
  ++a.count;
  a.sum += us;
  a.max = std::max(a.max, us);
  if (a.samples.size() < kMaxSamples) a.samples.push_back(static_cast<float>(us));
}

std::map<std::string, StepStats> StepTimings::stats() const {
  std::map<std::string, StepStats> out;
  for (const auto& [type, a] : acc_) {
    StepStats s;
    s.count = a.count;
    s.mean_us = a.count ? a.sum / static_cast<double>(a.count) : 0.0;
    s.max_us = a.max;
    if (!a.samples.empty()) {
      std::vector<float> v = a.samples;
      auto mid = v.begin() + static_cast<long>(v.size() / 2);
      std::nth_element(v.begin(), mid, v.end());
      s.median_us = *mid;
    }
    out[type] = s;
  }
  return out;
}

std::map<std::string, double> StepTimings::means() const {
  std::map<std::string, double> out;
  for (const auto& [type, a] : acc_) out[type] = a.count ? a.sum / static_cast<double>(a.count) : 0.0;
  return out;
}

}  // namespace meshnav::estimator
