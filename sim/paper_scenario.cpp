#include "sim/paper_scenario.h"

#include <algorithm>

namespace meshnav::sim {

PaperScenario PaperScenario::paper() {
  PaperScenario s;
  s.tags_p_TinI = {{100, {-0.19, 0.105, -0.07}}, {105, {0.05, -0.105, -0.07}}};
  s.anchors_p_AinG = {
      {101, {-1.308, -4.140, 0.66}}, {102, {1.742, -4.147, 1.881}}, {103, {2.914, 2.081, 2.172}},
      {104, {0.18, -4.13, 3.242}},   {106, {-1.772, 0.943, 3.256}}, {107, {-2.021, 1.814, 1.732}},
      {108, {-1.98, 0.069, 1.76}},   {109, {0.433, 4.105, 0.925}},  {110, {2.59, -0.2, 0.33}}};
  s.known_anchor_ids = {101, 102, 103, 104};
  return s;
}

std::vector<SensorId> PaperScenario::uwbDeviceIds() const {
  std::vector<SensorId> ids;
  for (const auto& [id, p] : tags_p_TinI) ids.push_back(id);
  for (const auto& [id, p] : anchors_p_AinG) ids.push_back(id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

}  // namespace meshnav::sim
