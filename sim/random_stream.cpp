#include "sim/random_stream.h"

#include <cmath>
#include <numbers>

namespace meshnav::sim {

namespace {
/// SplitMix64 finalizer: a bijective 64-bit mixer.
uint64_t splitMix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}
}  // namespace

RandomStream::RandomStream(uint64_t seed) : engine_(splitMix64(seed)) {}

uint64_t RandomStream::deriveSeed(uint64_t base, std::string_view stream) {
  uint64_t h = 0xCBF29CE484222325ull;  // FNV-1a of the stream name
  for (char ch : stream) {
    h ^= static_cast<unsigned char>(ch);
    h *= 0x100000001B3ull;
  }
  return splitMix64(splitMix64(base) ^ h);
}

double RandomStream::uniform() {
  return static_cast<double>(engine_() >> 11) * 0x1.0p-53;
}

double RandomStream::gaussian() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  const double u1 = 1.0 - uniform();  // (0, 1]: log is finite
  const double u2 = uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  const double phi = 2.0 * std::numbers::pi * u2;
  spare_ = r * std::sin(phi);
  has_spare_ = true;
  return r * std::cos(phi);
}

Eigen::Vector3d RandomStream::gaussian3(double sigma) {
  const double x = gaussian(sigma);
  const double y = gaussian(sigma);
  const double z = gaussian(sigma);
  return {x, y, z};
}

}  // namespace meshnav::sim
