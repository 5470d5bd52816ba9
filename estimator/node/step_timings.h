#pragma once
/// @file step_timings.h
/// @brief Wall-clock durations of filter steps by type ("propagate", "range_update", ...).

#include <chrono>
#include <map>
#include <string>
#include <vector>

namespace meshnav::estimator {

struct StepStats {
  int64_t count = 0;
  double mean_us = 0.0;
  double median_us = 0.0;
  double max_us = 0.0;
};

class StepTimings {
 public:
  /// Keeps at most this many samples per type for the median (the mean and max use all).
  static constexpr size_t kMaxSamples = 1u << 20;
  void add(const std::string& type, double us);
  std::map<std::string, StepStats> stats() const;
  std::map<std::string, double> means() const;

 private:
  struct Acc {
    int64_t count = 0;
    double sum = 0.0, max = 0.0;
    std::vector<float> samples;
  };
  std::map<std::string, Acc> acc_;
};

/// Measures the scope's duration into `timings` under `type`.
class ScopedStepTimer {
 public:
  ScopedStepTimer(StepTimings& timings, const char* type)
      : timings_(timings), type_(type), start_(std::chrono::steady_clock::now()) {}
  ~ScopedStepTimer() {
    const auto d = std::chrono::steady_clock::now() - start_;
    timings_.add(type_, std::chrono::duration<double, std::micro>(d).count());
  }
  ScopedStepTimer(const ScopedStepTimer&) = delete;
  ScopedStepTimer& operator=(const ScopedStepTimer&) = delete;

 private:
  StepTimings& timings_;
  const char* type_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace meshnav::estimator
