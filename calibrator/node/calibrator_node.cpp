/// @file calibrator_node.cpp
/// @brief CalibratorNode, first part: inputs (ranges, poses, anchors, commands), the collection
/// state and the time guard, periodic work and status. Building the observations and calibrating
/// an anchor are in calibrator_node_calibration.cpp.

#include "calibrator/node/calibrator_node.h"
#include "common/plausibility.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace meshnav::calib {

namespace {

/// Range sanity limits [m]: the project's one table (common/plausibility.h).
constexpr double kMinRangeM = plausible::kMinRange_m;
constexpr double kMaxRangeM = plausible::kMaxRange_m;

/// Extra slack before the pose history is trimmed, so that trimming is amortised [s].
constexpr double kPruneSlackS = 10.0;

std::string describe(const RangeSample& r) {
  return "range at t=" + formatSeconds(r.t) + " between " + std::to_string(r.id_initiator) + " and " +
         std::to_string(r.id_responder);
}

int64_t wallUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

/// Poses and ranges within the history window are data, however late: behind, the guard refuses
/// only beyond the window plus the offset (within that, "pose_too_old" says more).
TimeGuardOptions guardOptions(const CalibratorNodeOptions& o) {
  TimeGuardOptions g = o.time;
  g.max_behind_s = std::max(g.max_behind_s, o.history_window_s + o.time.max_offset_s);
  return g;
}

}  // namespace

const char* CalibratorNode::toString(State s) {
  switch (s) {
    case State::Idle: return "idle";
    case State::Collecting: return "collecting";
    case State::Calibrated: return "calibrated";
    case State::Refused: return "refused";
  }
  return "?";
}

CalibratorNode::CalibratorNode(const CalibratorOptions& options, const SystemSetup& setup, CalibratorSinks sinks,
                               const CalibratorNodeOptions& node_options, std::map<SensorId, size_t> vehicle_of_tag)
    : node_options_(node_options),
      setup_(setup),
      sinks_(std::move(sinks)),
      calibrator_(options),
      prior_source_(setup, options),
      collect_new_anchors_(node_options.collect_from_start),
      time_guard_(guardOptions(node_options)) {
  node_options_.validate();
  size_t n_vehicles = 1;
  for (const auto& [tag, v] : vehicle_of_tag) {
    if (!setup_.isTag(tag))
      throw std::invalid_argument("calibrator: vehicle_of_tag names " + std::to_string(tag) + ", not a tag of the setup");
    n_vehicles = std::max(n_vehicles, v + 1);
  }
  vehicle_of_tag_ = std::move(vehicle_of_tag);
  histories_.resize(n_vehicles);
  if (!(options.sigma_range_m > 0.0)) throw std::invalid_argument("calibrator option sigma_range must be > 0");
}

// --------------------------------------------------------------------------------------------
// Inputs
// --------------------------------------------------------------------------------------------

bool CalibratorNode::isUnknownAnchor(SensorId id, UwbType type) const {
  return id > 0 && !setup_.isTag(id) && !setup_.isKnownAnchor(id) && !setup_.isSensorInstanceId(id) &&
         type == UwbType::Anchor;
}

bool CalibratorNode::isReference(SensorId id) const {
  if (setup_.isTag(id) || setup_.isKnownAnchor(id)) return true;
  const auto it = tracks_.find(id);
  return it != tracks_.end() && it->second.state == State::Calibrated;
}

CalibratorNode::Track& CalibratorNode::track(SensorId x) {
  auto it = tracks_.find(x);
  if (it == tracks_.end()) {
    it = tracks_.emplace(x, Track{}).first;
    it->second.state = collect_new_anchors_ ? State::Collecting : State::Idle;
    if (newest_) it->second.next_auto_check = *newest_;
    spdlog::info("calibrator: new unknown anchor {} ({})", x, toString(it->second.state));
  }
  return it->second;
}

void CalibratorNode::onRange(const RangeSample& r) {
  diag_.count("ranges_received");
  if (!admitTime("RANGE", r.t)) return;
  if (!std::isfinite(r.range_m) || r.range_m < kMinRangeM || r.range_m > kMaxRangeM) {
    diag_.report("bad_range", describe(r) + ": range " + std::to_string(r.range_m) + " m is not finite or absurd");
    return;
  }
  if (r.id_initiator == r.id_responder || r.id_initiator <= 0 || r.id_responder <= 0) {
    diag_.report("bad_range", describe(r) + ": invalid device ids");
    return;
  }
  // Every end must be a device we can place now or later: a setup tag, a known anchor, or an
  // anchor of unknown position. Anything else (a tag not in the setup, the IMU/baro id) is unknown.
  for (const auto& [id, type] : {std::make_pair(r.id_initiator, r.type_initiator),
                                 std::make_pair(r.id_responder, r.type_responder)}) {
    if (!setup_.isTag(id) && !setup_.isKnownAnchor(id) && !isUnknownAnchor(id, type)) {
      diag_.report("unknown_device",
                   describe(r) + ": device " + std::to_string(id) + " (type '" + static_cast<char>(type) + "') " +
                       (setup_.isSensorInstanceId(id)
                            ? "has the id of the IMU or the baro (imu_id, baro_id in setup.yaml)"
                            : "is neither a tag of the setup nor an anchor"));
      return;
    }
  }
  // A range that comes a second time (a network that duplicates datagrams) is not collected
  // twice: keys (time, ids) are kept over time_max_offset of data time.
  if (newest_) {
    const int64_t oldest = (*newest_ - Duration::fromSec(node_options_.time.max_offset_s)).us;
    while (!seen_ranges_.empty() && std::get<0>(*seen_ranges_.begin()) < oldest) seen_ranges_.erase(seen_ranges_.begin());
  }
  if (!seen_ranges_.emplace(r.t.us, r.id_initiator, r.id_responder).second) {
    diag_.report("RANGE:duplicate", describe(r) + " came a second time; dropped");
    return;
  }
  advance(r.t);
  bool kept = false, idle = false;
  for (const auto& [x, type] : {std::make_pair(r.id_initiator, r.type_initiator),
                                std::make_pair(r.id_responder, r.type_responder)}) {
    if (!isUnknownAnchor(x, type)) continue;
    Track& tr = track(x);
    if (tr.state == State::Collecting || tr.state == State::Refused) {
      addRange(x, tr, r);
      kept = true;
    } else if (tr.state == State::Idle) {
      idle = true;
    }
  }
  if (kept) {
    diag_.count("ranges_kept");
  } else {
    diag_.count(idle ? "ranges_not_collecting" : "ranges_not_needed");
  }
  runPeriodic();
}

void CalibratorNode::addRange(SensorId x, Track& track, const RangeSample& r) {
  track.ranges.push_back(r);
  ++track.ranges_by_device[r.id_initiator == x ? r.id_responder : r.id_initiator];
  if (static_cast<int64_t>(track.ranges.size()) > node_options_.max_ranges_per_anchor) {
    const RangeSample& old = track.ranges.front();
    auto it = track.ranges_by_device.find(old.id_initiator == x ? old.id_responder : old.id_initiator);
    if (it != track.ranges_by_device.end() && --it->second <= 0) track.ranges_by_device.erase(it);
    track.ranges.pop_front();
    diag_.count("ranges_evicted");
  }
}

void CalibratorNode::onPose(const PoseEstimate& p_in, size_t vehicle) {
  PoseEstimate p = p_in;
  const double qn = p.q_ItoG.norm();
  if (!p.p_IinG.allFinite() || !p.q_ItoG.coeffs().allFinite() || !(qn > 0.5 && qn < 2.0) ||
      !p.cov_p_m2.allFinite() || !p.cov_theta_rad2.allFinite()) {
    diag_.report("bad_pose", "pose at t=" + formatSeconds(p.t) + " has a non-finite value or a bad quaternion");
    return;
  }
  if (vehicle >= histories_.size()) {
    diag_.report("bad_pose", "pose at t=" + formatSeconds(p.t) + " of vehicle " + std::to_string(vehicle) +
                                 ", which carries no tag of the setup");
    return;
  }
  if (!admitTime("POSE", p.t)) return;
  std::vector<PoseEstimate>& poses = histories_[vehicle];
  p.q_ItoG.normalize();
  const Duration window = Duration::fromSec(node_options_.history_window_s);
  if (!poses.empty() && p.t < poses.back().t - window) {
    diag_.report("pose_too_old", "pose at t=" + formatSeconds(p.t) + " is older than the history window (newest " +
                                     formatSeconds(poses.back().t) + ")");
    return;
  }
  if (poses.empty() || p.t > poses.back().t) {
    poses.push_back(p);
  } else {
    auto it = std::lower_bound(poses.begin(), poses.end(), p.t,
                               [](const PoseEstimate& a, Timestamp t) { return a.t < t; });
    if (it != poses.end() && it->t == p.t) {
      *it = p;  // same instant: the newer message wins
    } else {
      poses.insert(it, p);
      diag_.count("poses_out_of_order");
    }
  }
  // Trim the history (amortised: only when the slack is exceeded).
  const Timestamp cutoff = poses.back().t - window;
  if (poses.front().t < cutoff - Duration::fromSec(kPruneSlackS)) {
    auto it = std::lower_bound(poses.begin(), poses.end(), cutoff,
                               [](const PoseEstimate& a, Timestamp t) { return a.t < t; });
    poses.erase(poses.begin(), it);
  }
  advance(p.t);
  runPeriodic();
}

void CalibratorNode::onAnchors(const std::vector<AnchorEstimate>& anchors) {
  std::map<SensorId, AnchorEstimate> beliefs;
  for (const auto& a : anchors) {
    if (a.id <= 0 || !a.p_AinG.allFinite() || !a.cov_p_m2.allFinite()) {
      diag_.report("bad_anchor_estimate", "anchor estimate of " + std::to_string(a.id) + " at t=" + formatSeconds(a.t) +
                                              " is invalid (id or non-finite value)");
      continue;
    }
    beliefs[a.id] = a;
  }
  beliefs_ = std::move(beliefs);  // the message holds every anchor the estimator knows
}

bool CalibratorNode::isRepeat(const CalibCommand& c) {
  CommandKey key{c.t.us, static_cast<int>(c.action), c.anchors};
  if (seen_commands_.count(key)) {
    diag_.report("CALIB_CMD:duplicate", "command issued at t=" + formatSeconds(c.t) +
                                            " came again (a resend or a duplicated datagram); already executed, ignored");
    return true;
  }
  seen_commands_.insert(key);
  command_order_.push_back(std::move(key));
  if (command_order_.size() > kMaxCommandKeys) {
    seen_commands_.erase(command_order_.front());
    command_order_.pop_front();
  }
  return false;
}

void CalibratorNode::onCommand(const CalibCommand& c) {
  if (isRepeat(c)) return;
  std::vector<SensorId> ids;
  for (SensorId id : c.anchors) {
    if (id <= 0 || setup_.isTag(id) || setup_.isKnownAnchor(id) || setup_.isSensorInstanceId(id)) {
      diag_.report("bad_command", "command names " + std::to_string(id) + ", which is not an anchor of unknown position (" +
                                      (setup_.isSensorInstanceId(id) ? "the IMU's or the baro's id"
                                       : id <= 0                     ? "not a device id"
                                                                     : "a tag or a known anchor") +
                                      "); ignored for it");
      continue;
    }
    ids.push_back(id);
  }
  const bool all = c.anchors.empty();
  if (!all && ids.empty()) return;
  switch (c.action) {
    case CalibCommand::Action::Collect:
      if (all) {
        collect_new_anchors_ = true;
        for (auto& [x, tr] : tracks_)
          if (tr.state == State::Idle) startCollecting(x, tr);
      } else {
        for (SensorId x : ids) startCollecting(x, track(x));
      }
      break;
    case CalibCommand::Action::Calibrate: {
      if (all)
        for (const auto& [x, tr] : tracks_)
          if (tr.state == State::Collecting || tr.state == State::Refused) ids.push_back(x);
      for (SensorId x : ids) {
        Track& tr = track(x);
        if (tr.state == State::Calibrated) {
          spdlog::info("calibrator: anchor {} is already calibrated; Calibrate ignored (Collect it to re-calibrate)", x);
          diag_.count("calibrate_already_calibrated");
        } else if (tr.state == State::Idle) {
          tr.reason = "not collecting (aborted, or no Collect yet)";
          diag_.report("calibrate_not_collecting", "Calibrate for anchor " + std::to_string(x) + ": " + tr.reason);
        } else {
          calibrateAnchor(x, tr, buildObservations(x, tr), false);
        }
      }
      publishStatus();
      break;
    }
    case CalibCommand::Action::Abort:
      if (all) {
        collect_new_anchors_ = false;
        for (auto& [x, tr] : tracks_)
          if (tr.state != State::Calibrated) stopCollecting(tr);
      } else {
        for (SensorId x : ids) {
          Track& tr = track(x);
          if (tr.state != State::Calibrated) stopCollecting(tr);
        }
      }
      break;
    default:
      diag_.report("bad_command", "unknown command action " + std::to_string(static_cast<int>(c.action)));
      break;
  }
}

void CalibratorNode::tick(Timestamp now) {
  if (newest_ && now <= *newest_) {
    runPeriodic();
    return;
  }
  if (!admitTime("tick", now)) {
    runPeriodic();
    return;
  }
  advance(now);
  runPeriodic();
}

// --------------------------------------------------------------------------------------------
// Collection state
// --------------------------------------------------------------------------------------------

void CalibratorNode::startCollecting(SensorId x, Track& tr) {
  if (tr.state == State::Calibrated)
    spdlog::info("calibrator: anchor {} collects anew; its calibration is forgotten (no longer a reference)", x);
  tr.state = State::Collecting;
  tr.ranges.clear();
  tr.ranges_by_device.clear();
  tr.reason.clear();
  tr.result.reset();
  tr.next_auto_check = newest_.value_or(Timestamp{});
}

void CalibratorNode::stopCollecting(Track& tr) {
  tr.state = State::Idle;
  tr.ranges.clear();
  tr.ranges_by_device.clear();
  tr.reason.clear();
}

void CalibratorNode::advance(Timestamp t) {
  if (!newest_ || t > *newest_) newest_ = t;
}

bool CalibratorNode::admitTime(const std::string& kind, Timestamp t) {
  const TimeGuard::Verdict v = time_guard_.admit(kind, t, diag_);
  if (v == TimeGuard::Verdict::Ahead || v == TimeGuard::Verdict::Behind) return false;
  if (v == TimeGuard::Verdict::Rebased && time_guard_.lastJump().us < 0) {
    // The data time was ahead of every input: follow the inputs back; poses from beyond go.
    newest_ = t;
    next_status_.reset();
    next_prune_.reset();
    for (auto& poses : histories_)
      poses.erase(std::upper_bound(poses.begin(), poses.end(), t,
                                   [](Timestamp x, const PoseEstimate& p) { return x < p.t; }),
                  poses.end());
    for (auto& [id, tr] : tracks_) tr.next_auto_check = t;
  }
  return true;
}

// --------------------------------------------------------------------------------------------
// Periodic work and status
// --------------------------------------------------------------------------------------------

void CalibratorNode::pruneOldTagRanges() {
  const Timestamp cutoff = *newest_ - Duration::fromSec(node_options_.history_window_s);
  for (auto& [x, tr] : tracks_) {
    if (tr.state != State::Collecting && tr.state != State::Refused) continue;
    std::deque<RangeSample> kept;
    int64_t dropped = 0;
    for (const RangeSample& r : tr.ranges) {
      const SensorId ref = r.id_initiator == x ? r.id_responder : r.id_initiator;
      if (setup_.isTag(ref) && r.t < cutoff) {
        ++dropped;
        auto it = tr.ranges_by_device.find(ref);
        if (it != tr.ranges_by_device.end() && --it->second <= 0) tr.ranges_by_device.erase(it);
      } else {
        kept.push_back(r);
      }
    }
    if (dropped > 0) {
      tr.ranges.swap(kept);
      diag_.count("ranges_dropped_no_pose", dropped);
    }
  }
}

void CalibratorNode::runPeriodic() {
  if (!newest_) return;
  const Timestamp now = *newest_;
  if (!next_prune_ || now >= *next_prune_) {
    if (next_prune_) pruneOldTagRanges();
    next_prune_ = now + Duration::fromSec(kPruneSlackS);
  }
  for (auto& [x, tr] : tracks_) {
    if (node_options_.auto_mode && (tr.state == State::Collecting || tr.state == State::Refused)) checkAuto(x, tr);
    else if (node_options_.retry_refused && tr.state == State::Refused) checkAuto(x, tr);
  }
  const Duration period = Duration::fromSec(node_options_.status_period_s);
  if (!next_status_) next_status_ = now;
  if (now >= *next_status_) {
    // Next multiple of the period after now (a jump in time emits one status, not many).
    const int64_t k = (now - *next_status_).us / period.us + 1;
    next_status_ = *next_status_ + Duration{k * period.us};
    publishStatus();
  }
}

void CalibratorNode::publishStatus() {
  if (sinks_.status) sinks_.status(status());
}

CalibStatus CalibratorNode::status() const {
  CalibStatus s;
  s.t = newest_.value_or(Timestamp{});
  s.wall_utime = wallUtime();
  for (const auto& [x, tr] : tracks_) {
    CalibAnchorStatus a;
    a.id = x;
    a.state = toString(tr.state);
    a.reason = tr.reason;
    if (tr.state == State::Calibrated && tr.result) {
      a.n_ranges = tr.result->n_observations;
      a.n_refs = static_cast<int32_t>(tr.result->references.size());
    } else {
      a.n_ranges = static_cast<int64_t>(tr.ranges.size());
      for (const auto& [dev, n] : tr.ranges_by_device) a.n_refs += (n > 0 && isReference(dev)) ? 1 : 0;
    }
    s.anchors.push_back(a);
  }
  s.counters = diag_.snapshot();
  s.counters["ranges_waiting_for_pose"] = last_waiting_for_pose_;
  s.counters["ranges_waiting_for_reference"] = last_waiting_for_reference_;
  s.counters["poses_held"] = static_cast<int64_t>(poseHistorySize());
  s.counters["anchors_calibrated"] = static_cast<int64_t>(calibratedAnchors().size());
  return s;
}

size_t CalibratorNode::poseHistorySize() const {
  size_t n = 0;
  for (const auto& poses : histories_) n += poses.size();
  return n;
}

std::vector<SensorId> CalibratorNode::calibratedAnchors() const {
  std::vector<SensorId> out;
  for (const auto& [x, tr] : tracks_)
    if (tr.state == State::Calibrated) out.push_back(x);
  return out;
}

}  // namespace meshnav::calib
