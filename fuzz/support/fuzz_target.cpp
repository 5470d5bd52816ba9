#include "fuzz/support/fuzz_target.h"

#include <cstdio>
#include <cstdlib>

namespace meshnav::fuzz {

void fail(const std::string& what) {
  std::fprintf(stderr, "fuzz finding: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

}  // namespace meshnav::fuzz
