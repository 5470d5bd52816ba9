#include "pipeline/fleet_calibrator_feed.h"

#include <stdexcept>
#include <string>

#include "pipeline/anchor_belief_intersection.h"
#include "pipeline/fleet.h"

namespace meshnav::pipeline {

FleetCalibratorFeed::FleetCalibratorFeed(const std::vector<Vehicle>& vehicles, const SystemSetup& fleet_setup,
                                         Diagnostics& diag)
    : fleet_setup_(fleet_setup), diag_(diag) {
  if (vehicles.empty()) throw std::invalid_argument("fleet calibrator feed: no vehicle");
  for (size_t v = 0; v < vehicles.size(); ++v) {
    for (const auto& [tag, lever] : vehicles[v].setup.rel_tag_positions) {
      if (!fleet_setup.isTag(tag))
        throw std::invalid_argument("pipeline: tag " + std::to_string(tag) + " of vehicle " + vehicles[v].name +
                                    " is not in the fleet's setup");
      vehicle_of_tag_[tag] = v;
    }
    setups_.push_back(vehicles[v].setup);
  }
  beliefs_.resize(vehicles.size());
}

bool FleetCalibratorFeed::betweenVehicles(const RangeSample& r) const {
  const auto a = vehicle_of_tag_.find(r.id_initiator), b = vehicle_of_tag_.find(r.id_responder);
  return a != vehicle_of_tag_.end() && b != vehicle_of_tag_.end() && a->second != b->second;
}

bool FleetCalibratorFeed::forCalibrator(const RangeSample& r) {
  if (setups_.size() == 1) return true;
  if (betweenVehicles(r)) {
    diag_.count("inter_vehicle_range_not_for_calibrator");
    return false;
  }
  if (fleet_setup_.isTag(r.id_initiator) || fleet_setup_.isTag(r.id_responder)) return true;
  // The anchors' mesh is heard by every vehicle: the same sample in several datasets is one range.
  constexpr int64_t kKeepUs = 10'000'000;
  while (!mesh_ranges_.empty() && std::get<0>(*mesh_ranges_.begin()) < r.t.us - kKeepUs)
    mesh_ranges_.erase(mesh_ranges_.begin());
  const auto key = pairKey(r.id_initiator, r.id_responder);
  if (mesh_ranges_.emplace(r.t.us, key.first, key.second).second) return true;
  diag_.count("mesh_range_from_another_vehicle");
  return false;
}

std::vector<AnchorEstimate> FleetCalibratorFeed::anchorsFrom(size_t v, const std::vector<AnchorEstimate>& anchors) {
  auto& mine = beliefs_.at(v);
  if (setups_.size() == 1) return anchors;
  mine.clear();
  for (const auto& a : anchors) mine[a.id] = a;
  std::vector<std::vector<AnchorEstimate>> per_vehicle;
  for (const auto& beliefs : beliefs_) {
    per_vehicle.emplace_back();
    for (const auto& [id, a] : beliefs) per_vehicle.back().push_back(a);
  }
  return AnchorBeliefIntersection::fuseVehicles(per_vehicle);
}

AnchorInit FleetCalibratorFeed::forVehicle(size_t v, const AnchorInit& a) const {
  return setups_.size() == 1 ? a : restrictToVehicle(a, setups_.at(v), fleet_setup_);
}

}  // namespace meshnav::pipeline
