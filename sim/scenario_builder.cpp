#include "sim/scenario_builder.h"

#include <array>
#include <utility>

#include "sim/anchor_layout.h"

namespace meshnav::sim {

PaperScenario buildScenario(const SimulationOptions& o) {
  if (o.isPaperScenario()) return PaperScenario::paper();
  PaperScenario s = PaperScenario::paper();
  const std::array<std::pair<SensorId, Eigen::Vector3d>, 3> tags{
      {{100, s.tags_p_TinI.at(100)}, {105, s.tags_p_TinI.at(105)}, {99, Eigen::Vector3d(0.0, 0.0, 0.12)}}};
  s.tags_p_TinI.clear();
  // The anchor ids skip the single vehicle's tag ids, also for a fleet's further vehicles (one world).
  std::set<SensorId> tag_ids;
  for (int i = 0; i < o.n_tags; ++i) {
    s.tags_p_TinI[tags[i].first + o.tag_id_offset] = tags[i].second;
    tag_ids.insert(tags[i].first);
  }
  const Hall hall = o.hall();
  s.hall_min_m = hall.min_m;
  s.hall_max_m = hall.max_m;
  const AnchorLayout layout =
      AnchorLayout::generate(o.anchor_layout, hall, o.n_known_anchors, o.n_unknown_anchors, tag_ids,
                             o.layout_seed.value_or(o.seed));
  s.anchors_p_AinG = layout.anchors_p_AinG;
  s.known_anchor_ids = layout.known_ids;
  return s;
}

}  // namespace meshnav::sim
