/// @file factorized_covariance_sets.cpp
/// @brief FactorizedCovariance, DAH joint sets (issue 10): instances that always take part in a DAH
/// update together, so that the correlations among them are never approximated. Used for the
/// anchors calibrated (or re-run) together: their errors share the trajectory's error, a
/// correlation that DAH's per-instance correction cannot build between two instances through a
/// third one (docs/modular_estimator.md, "Joint sets").

#include <algorithm>
#include <stdexcept>
#include <string>

#include "estimator/filter/factorized_covariance.h"

namespace meshnav::estimator {

void FactorizedCovariance::joinSet(const std::vector<SensorId>& ids) {
  std::vector<SensorId> merged;
  for (SensorId id : ids)
    if (has(id)) merged.push_back(id);
  auto sets = sets_ ? std::make_shared<JointSets>(*sets_) : std::make_shared<JointSets>();
  // Absorb every existing set that shares a member with the new one.
  for (auto it = sets->begin(); it != sets->end();) {
    const bool overlaps = std::any_of(it->begin(), it->end(), [&](SensorId m) {
      return std::find(merged.begin(), merged.end(), m) != merged.end();
    });
    if (overlaps) {
      merged.insert(merged.end(), it->begin(), it->end());
      it = sets->erase(it);
    } else {
      ++it;
    }
  }
  std::sort(merged.begin(), merged.end());
  merged.erase(std::unique(merged.begin(), merged.end()), merged.end());
  if (merged.size() >= 2) sets->push_back(std::move(merged));
  sets_ = sets->empty() ? nullptr : std::shared_ptr<const JointSets>(std::move(sets));
}

std::vector<SensorId> FactorizedCovariance::jointSet(SensorId id) const {
  if (!sets_) return {};
  for (const auto& s : *sets_)
    if (std::binary_search(s.begin(), s.end(), id)) return s;
  return {};
}

void FactorizedCovariance::leaveSet(SensorId id) {
  if (jointSet(id).empty()) return;
  auto sets = std::make_shared<JointSets>(*sets_);
  for (auto& s : *sets) std::erase(s, id);
  std::erase_if(*sets, [](const std::vector<SensorId>& s) { return s.size() < 2; });
  sets_ = sets->empty() ? nullptr : std::shared_ptr<const JointSets>(std::move(sets));
}

bool FactorizedCovariance::namesJointSet(const Linearization& lin) const {
  if (!sets_) return false;
  return std::any_of(lin.blocks.begin(), lin.blocks.end(),
                     [&](const JacobianBlock& jb) { return !jointSet(jb.id).empty(); });
}

std::vector<int> FactorizedCovariance::dahParticipants(const Linearization& lin) const {
  std::vector<int> part;
  for (const JacobianBlock& jb : lin.blocks) {
    if (!has(jb.id)) throw std::logic_error("FactorizedCovariance::update: no instance " + std::to_string(jb.id));
    part.push_back(index(jb.id));
    for (SensorId m : jointSet(jb.id))
      if (m != jb.id) part.push_back(index(m));
  }
  std::sort(part.begin(), part.end());
  part.erase(std::unique(part.begin(), part.end()), part.end());
  return part;
}

}  // namespace meshnav::estimator
