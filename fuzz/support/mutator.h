#pragma once
/// @file mutator.h
/// @brief Deterministic byte mutations for the replay driver: the same seed gives the same inputs
/// on every machine, so a CTest failure reproduces. A small stand-in for libFuzzer's mutator
/// (no coverage feedback) that still reaches the typical faults of text and binary parsers:
/// flipped bits, cut and repeated pieces, numbers at the edges of their type, lines spliced from
/// another seed.

#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace meshnav::fuzz {

class Mutator {
 public:
  explicit Mutator(uint64_t seed) : rng_(seed) {}
  /// A mutant of `input`: 1 to 4 edits, some taking a piece of `other` (another corpus file).
  std::string mutate(const std::string& input, const std::string& other);

 private:
  size_t below(size_t n);  ///< uniform in [0, n), 0 when n == 0
  void editOnce(std::string& s, const std::string& other);

  std::mt19937_64 rng_;
};

}  // namespace meshnav::fuzz
