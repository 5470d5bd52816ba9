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
                   "Publishes N malformed messages on CH (N-1 random byte strings and one MISSION_STATUS).");
  std::string ch, url;
  int n = 3;
  cli.optional("channel", ch, "channel")->type_name("CH")->required();
  cli.option("count", n, "messages")->type_name("N")->check(CLI::NonNegativeNumber);
  cli.optional("lcm-url", url, "LCM provider")->type_name("URL");
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  lcm::LCM lcm(url);
  if (!lcm.good()) return 1;
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
