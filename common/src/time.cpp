#include "common/time.h"

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
  char buf[48];
  const bool neg = t.us < 0;
  // Magnitude in unsigned arithmetic: -INT64_MIN does not fit an int64.
  const uint64_t a = neg ? uint64_t{0} - static_cast<uint64_t>(t.us) : static_cast<uint64_t>(t.us);
  std::snprintf(buf, sizeof(buf), "%s%llu.%06llu", neg ? "-" : "", static_cast<unsigned long long>(a / 1000000),
                static_cast<unsigned long long>(a % 1000000));
  return buf;
}

}  // namespace meshnav
