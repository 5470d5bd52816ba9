#include "transport/wire_versions.h"

namespace meshnav::transport {

int64_t encodedFingerprint(const void* data, size_t size) {
  if (size < 8) return 0;
  uint64_t found = 0;
  const auto* b = static_cast<const uint8_t*>(data);
  for (int i = 0; i < 8; ++i) found = (found << 8) | b[i];
  return static_cast<int64_t>(found);
}

void writeFingerprint(void* data, int64_t hash) {
  auto* b = static_cast<uint8_t*>(data);
  const auto h = static_cast<uint64_t>(hash);
  for (int i = 0; i < 8; ++i) b[i] = static_cast<uint8_t>(h >> (56 - 8 * i));
}

}  // namespace meshnav::transport
