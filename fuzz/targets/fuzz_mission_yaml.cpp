/// @file fuzz_mission_yaml.cpp
/// @brief Fuzz target: mission YAML through parseMission. A refusal names the file; an accepted
/// mission has finite, non-negative step times in order and ids on every `remove`.
#include <cmath>
#include <string>

#include "fuzz/support/fuzz_target.h"
#include "mission/mission.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string source = "fuzz_mission.yaml";
  try {
    const mission::Mission m = mission::parseMission(text, source);
    for (size_t i = 0; i < m.steps.size(); ++i) {
      const auto& s = m.steps[i];
      fuzz::require(std::isfinite(s.t_s) && s.t_s >= 0.0, "mission step with a negative or non-finite time");
      if (i > 0) fuzz::require(m.steps[i - 1].t_s <= s.t_s, "mission steps out of time order");
      if (s.action == mission::MissionAction::Remove) fuzz::require(!s.anchors.empty(), "remove without anchors");
      for (SensorId id : s.anchors) fuzz::require(id > 0, "mission with a non-positive anchor id");
      (void)s.describe();
    }
  } catch (const std::runtime_error& e) {
    fuzz::require(std::string(e.what()).find(source) != std::string::npos,
                  std::string("mission refused without naming the file: ") + e.what());
  } catch (const std::exception& e) {
    fuzz::fail(std::string("unexpected exception: ") + e.what());
  }
  return 0;
}
