#include "common/time.h"

#include <charconv>
#include <cstdio>
#include <stdexcept>

namespace meshnav {

namespace time_detail {
void throwOutOfRange(double s) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), "time %.6g s is not finite or beyond +-%.0e s", s, kMaxTimeSeconds);
  throw std::out_of_range(buf);
}
}  // namespace time_detail

std::string formatSeconds(Timestamp t) {
  // "%s%llu.%06llu" (sign, whole seconds, microseconds), without snprintf: every row of the
  // estimator's CSV files takes one.
  char buf[48];
  char* p = buf;
  const bool neg = t.us < 0;
  // Magnitude in unsigned arithmetic: -INT64_MIN does not fit an int64.
  const uint64_t a = neg ? uint64_t{0} - static_cast<uint64_t>(t.us) : static_cast<uint64_t>(t.us);
  if (neg) *p++ = '-';
  p = std::to_chars(p, buf + sizeof(buf), a / 1000000).ptr;
  *p++ = '.';
  uint64_t frac = a % 1000000;
  for (int i = 5; i >= 0; --i, frac /= 10) p[i] = static_cast<char>('0' + frac % 10);
  return std::string(buf, p + 6);
}

}  // namespace meshnav
