#pragma once
/// @file random_stream.h
/// @brief Deterministic random numbers for the simulator.
///
/// The engine is std::mt19937_64 (its output sequence is fixed by the C++ standard); the
/// distributions are implemented here (not std::normal_distribution, whose algorithm is
/// implementation-defined), so a seed gives the same dataset with any standard library:
///   uniform u = (x >> 11) · 2^−53 ∈ [0, 1)  (53 random mantissa bits),
///   Gaussian by Box–Muller: n = √(−2 ln(1 − u₁)) · cos(2π u₂) (the sine branch is kept for the next call).
/// Independent streams for independent purposes (IMU noise, ranges, ...) are derived with
/// `deriveSeed`, so that changing one option does not reshuffle the noise of another sensor.

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string_view>

namespace meshnav::sim {

class RandomStream {
 public:
  explicit RandomStream(uint64_t seed);

  /// Seed of an independent stream named `stream` derived from `base` (SplitMix64 of the mix).
  static uint64_t deriveSeed(uint64_t base, std::string_view stream);

  /// Uniform in [0, 1).
  double uniform();
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Standard normal N(0, 1).
  double gaussian();
  /// N(0, σ²).
  double gaussian(double sigma) { return sigma * gaussian(); }
  /// Three independent N(0, σ²).
  Eigen::Vector3d gaussian3(double sigma);
  /// True with probability p.
  bool bernoulli(double p) { return uniform() < p; }

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace meshnav::sim
