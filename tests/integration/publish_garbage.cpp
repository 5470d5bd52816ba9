/// meshnav_publish_garbage: publishes malformed messages (random bytes, and a valid message of
/// the wrong type) on a channel, for tests that a running process survives and counts them.
///   meshnav_publish_garbage --channel RANGE [--count N] [--lcm-url URL]
#include <lcm/lcm-cpp.hpp>

#include <cstdio>
#include <random>
#include <vector>

#include "common/cli.h"
#include "transport/convert.h"

int main(int argc, char** argv) {
  meshnav::Cli cli("meshnav_publish_garbage",
                   "meshnav_publish_garbage --channel CH [--count N] [--lcm-url URL]\n"
                   "  publishes N malformed messages on CH (N-1 random byte strings and one MISSION_STATUS)\n");
  cli.option("channel").option("count").option("lcm-url");
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  if (!cli.has("channel")) return 2;
  lcm::LCM lcm(cli.get("lcm-url"));
  if (!lcm.good()) return 1;
  const std::string ch = cli.get("channel");
  const int n = static_cast<int>(cli.getInt("count", 3));
  std::mt19937 rng(42);
  for (int i = 0; i + 1 < n; ++i) {
    std::vector<uint8_t> bytes(static_cast<size_t>(1 + i * 37 % 200));
    for (auto& b : bytes) b = static_cast<uint8_t>(rng());
    lcm.publish(ch, bytes.data(), static_cast<unsigned>(bytes.size()));
  }
  if (n > 0) {
    const auto wrong = meshnav::transport::toLcm(meshnav::MissionStatus{});
    lcm.publish(ch, &wrong);
  }
  std::printf("published %d malformed messages on %s\n", n, ch.c_str());
  return 0;
}
