/// @file input_settler.cpp
/// @brief InputSettler: inputs released in the canonical order once settled (input_settler.h).

#include "estimator/node/input_settler.h"

#include <algorithm>

namespace meshnav::estimator {

/// The streams whose order the watermark relies on (a fleet's peer ranges are routed inside one
/// process and come only while a peer is ranged: not a stream that must pass).
bool InputSettler::isStreamInput(const EstimatorInput& in) {
  return std::holds_alternative<ImuSample>(in) || std::holds_alternative<RangeSample>(in) ||
         std::holds_alternative<BaroSample>(in) || std::holds_alternative<HeightSample>(in);
}

bool InputSettler::add(const EstimatorInput& in) {
  const InputOrder key = inputOrder(in);
  const Timestamp t = inputTime(in);
  if (isStreamInput(in)) {
    auto [it, fresh] = newest_by_kind_.emplace(inputKindRank(in), t);
    if (!fresh) it->second = std::max(it->second, t);
    newest_ = newest_ ? std::max(*newest_, t) : t;
  }
  if (released_ && key < *released_) return false;
  held_.emplace_hint(held_.upper_bound(key), key, in);
  return true;
}

std::optional<Timestamp> InputSettler::watermark() const {
  if (!newest_by_kind_.count(InputKind<ImuSample>::rank) ||
      (expect_ranges_ && !newest_by_kind_.count(InputKind<RangeSample>::rank)))
    return std::nullopt;
  Timestamp w = newest_by_kind_.begin()->second;
  for (const auto& [kind, t] : newest_by_kind_) w = std::min(w, t);
  return w;
}

std::vector<EstimatorInput> InputSettler::takeSettled() {
  std::vector<EstimatorInput> out;
  const std::optional<Timestamp> w = watermark();
  while (!held_.empty()) {
    const auto it = held_.begin();
    const Timestamp t{it->first.t_us};
    const bool below_watermark = w && t < *w;
    const bool held_too_long = newest_ && (*newest_ - t).sec() >= max_hold_s_;
    if (!below_watermark && !held_too_long) break;
    released_ = it->first;
    out.push_back(std::move(it->second));
    held_.erase(it);
  }
  return out;
}

std::vector<EstimatorInput> InputSettler::takeAll() {
  std::vector<EstimatorInput> out;
  out.reserve(held_.size());
  for (auto& [key, in] : held_) {
    released_ = key;
    out.push_back(std::move(in));
  }
  held_.clear();
  return out;
}

void InputSettler::clear() {
  held_.clear();
  newest_by_kind_.clear();
  newest_.reset();
  released_.reset();
}

}  // namespace meshnav::estimator
