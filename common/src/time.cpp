#include "common/time.h"

#include <cstdio>

namespace meshnav {

std::string formatSeconds(Timestamp t) {
  char buf[48];
  const int64_t us = t.us;
  const bool neg = us < 0;
  const int64_t a = neg ? -us : us;
  std::snprintf(buf, sizeof(buf), "%s%lld.%06lld", neg ? "-" : "", static_cast<long long>(a / 1000000),
                static_cast<long long>(a % 1000000));
  return buf;
}

}  // namespace meshnav
