/// @file calibrator_node_calibration.cpp
/// @brief CalibratorNode, second part: the observations of an anchor under calibration (tag
/// positions interpolated from the pose history, references from calibrated anchors), the
/// calibration itself with its result, and the automatic trigger once the geometry is good.
/// The first part, calibrator_node.cpp, holds inputs, collection state and status.

#include <spdlog/spdlog.h>

#include "calibrator/calibration_problem.h"
#include "calibrator/node/calibrator_node.h"
#include "calibrator/reference_geometry.h"
#include "common/pose_interpolation.h"

namespace meshnav::calib {

// --------------------------------------------------------------------------------------------
// Observations
// --------------------------------------------------------------------------------------------

std::optional<std::pair<Eigen::Vector3d, Eigen::Matrix3d>> CalibratorNode::tagPosition(SensorId tag,
                                                                                      Timestamp t) const {
  const auto lever = setup_.rel_tag_positions.find(tag);
  if (lever == setup_.rel_tag_positions.end()) return std::nullopt;
  const auto& opt = calibrator_.options();
  const auto pose = interpolateEstimate(historyOf(tag), t, Duration::fromSec(opt.max_pose_gap_s));
  if (!pose) return std::nullopt;
  return tagPositionAtPose(*pose, lever->second, opt.min_tag_position_sigma_m);
}

const std::vector<PoseEstimate>& CalibratorNode::historyOf(SensorId tag) const {
  const auto it = vehicle_of_tag_.find(tag);
  return histories_[it == vehicle_of_tag_.end() ? 0 : it->second];
}

std::optional<std::pair<Eigen::Vector3d, Eigen::Matrix3d>> CalibratorNode::anchorReference(SensorId id) const {
  if (const auto k = setup_.abs_anchor_positions.find(id); k != setup_.abs_anchor_positions.end()) {
    const auto sig = setup_.abs_anchor_sigmas_m.find(id);
    const double s = sig == setup_.abs_anchor_sigmas_m.end() ? 0.0 : sig->second;
    return std::make_pair(k->second, Eigen::Matrix3d(s * s * Eigen::Matrix3d::Identity()));
  }
  const auto it = tracks_.find(id);
  if (it == tracks_.end() || it->second.state != State::Calibrated || !it->second.result) return std::nullopt;
  if (const auto b = beliefs_.find(id); b != beliefs_.end()) return std::make_pair(b->second.p_AinG, b->second.cov_p_m2);
  return std::make_pair(it->second.result->p_AinG, it->second.result->cov_p_m2);
}

CalibratorNode::Built CalibratorNode::buildObservations(SensorId x, Track& tr) {
  Built b;
  const auto& opt = calibrator_.options();
  std::deque<RangeSample> kept;
  for (const RangeSample& r : tr.ranges) {
    CalibObservation o = rangeObservation(r, x, opt);
    const SensorId ref = o.ref_id;
    if (setup_.isTag(ref)) {
      if (const auto tp = tagPosition(ref, r.t)) {
        o.p_RinG = tp->first;
        o.cov_p_RinG_m2 = tp->second;
        b.obs.push_back(o);
      } else if (const auto& poses = historyOf(ref); poses.empty() || r.t > poses.back().t) {
        ++b.waiting_for_pose;  // the pose may still come
      } else {
        ++b.dropped_no_pose;   // a gap in (or before) the pose history: never usable
        auto it = tr.ranges_by_device.find(ref);
        if (it != tr.ranges_by_device.end() && --it->second <= 0) tr.ranges_by_device.erase(it);
        continue;
      }
    } else if (const auto ar = anchorReference(ref)) {
      o.p_RinG = ar->first;
      o.cov_p_RinG_m2 = ar->second;
      b.obs.push_back(o);
    } else {
      ++b.waiting_for_reference;  // the other anchor is not calibrated (yet)
    }
    kept.push_back(r);
  }
  tr.ranges.swap(kept);
  if (b.dropped_no_pose > 0) diag_.count("ranges_dropped_no_pose", b.dropped_no_pose);
  return b;
}

// --------------------------------------------------------------------------------------------
// Calibration
// --------------------------------------------------------------------------------------------

void CalibratorNode::calibrateAnchor(SensorId x, Track& tr, Built built, bool automatic,
                                     const CalibratorOptions* options) {
  last_waiting_for_pose_ = built.waiting_for_pose;
  last_waiting_for_reference_ = built.waiting_for_reference;
  const Timestamp stamp = newest_.value_or(Timestamp{});
  CalibrationResult res = (options ? AnchorCalibrator(*options) : calibrator_)
                              .calibrate(x, built.obs, prior_source_.priors(x), stamp);
  const char* how = automatic ? "automatic" : "commanded";
  if (res.ok()) {
    std::string refs;
    for (const auto& r : res.references) refs += (refs.empty() ? "" : ",") + std::to_string(r.ref_id);
    spdlog::info("calibrator: anchor {} calibrated ({}, t={} s): p_AinG [{:.3f} {:.3f} {:.3f}] m, sigma [{:.3f} "
                 "{:.3f} {:.3f}] m, {} inliers, {} outliers, refs {}",
                 x, how, formatSeconds(stamp), res.p_AinG.x(), res.p_AinG.y(), res.p_AinG.z(),
                 std::sqrt(res.cov_p_m2(0, 0)), std::sqrt(res.cov_p_m2(1, 1)), std::sqrt(res.cov_p_m2(2, 2)),
                 res.n_inliers, res.n_outliers, refs);
    tr.state = State::Calibrated;
    tr.reason.clear();
    tr.ranges.clear();
    tr.ranges_by_device.clear();
    diag_.count("calibrations_ok");
    res.inliers.clear();  // per-observation flags are not needed after the fact
    tr.result = res;
    keepResult(res);
    if (sinks_.anchor_init) sinks_.anchor_init(res.toAnchorInit());
  } else {
    tr.state = State::Refused;
    tr.reason = std::string(calib::toString(res.status)) + ": " + res.reason;
    if (built.waiting_for_pose > 0 || built.waiting_for_reference > 0)
      tr.reason += " (" + std::to_string(built.waiting_for_pose) + " ranges wait for a tag pose, " +
                   std::to_string(built.waiting_for_reference) + " for a reference anchor)";
    tr.next_auto_check = stamp + Duration::fromSec(node_options_.auto_retry_period_s);
    spdlog::warn("calibrator: anchor {} refused ({}, t={} s): {}", x, how, formatSeconds(stamp), tr.reason);
    diag_.count("calibrations_refused");
    res.inliers.clear();
    keepResult(std::move(res));
  }
}

void CalibratorNode::keepResult(CalibrationResult res) {
  results_.push_back(std::move(res));
  if (results_.size() > kMaxResults) results_.erase(results_.begin());
}

void CalibratorNode::checkAuto(SensorId x, Track& tr) {
  if (!newest_ || *newest_ < tr.next_auto_check) return;
  tr.next_auto_check = *newest_ + Duration::fromSec(node_options_.auto_check_period_s);
  Built built = buildObservations(x, tr);
  const auto& opt = calibrator_.options();
  // What the criterion waits for, kept as the collecting anchor's reason (CALIB_STATUS, the end
  // of meshnav_run): an anchor that is never calibrated says why. A refused anchor keeps its
  // refusal as the reason.
  const auto waiting = [&](const std::string& what) {
    if (tr.state == State::Collecting) tr.reason = "automatic calibration waits: " + what;
  };
  // 1. enough usable ranges.
  if (static_cast<int>(built.obs.size()) < node_options_.auto_min_ranges) {
    waiting(std::to_string(built.obs.size()) + " ranges with a reference position, needs " +
            std::to_string(node_options_.auto_min_ranges));
    return;
  }
  // 2. enough reference devices with enough ranges each.
  std::map<SensorId, int> per_ref;
  for (const auto& o : built.obs) ++per_ref[o.ref_id];
  int n_refs = 0;
  for (const auto& [id, n] : per_ref) n_refs += n >= opt.min_measurements_per_reference ? 1 : 0;
  if (n_refs < node_options_.auto_min_references) {
    waiting(std::to_string(n_refs) + " reference devices with " + std::to_string(opt.min_measurements_per_reference) +
            " ranges each, needs " + std::to_string(node_options_.auto_min_references));
    return;
  }
  // 3. the library's refusal checks with the stricter spreads: the tags span a volume.
  CalibratorOptions strict = opt;
  strict.min_plane_spread_m = std::max(opt.min_plane_spread_m, node_options_.auto_min_plane_spread_m);
  strict.min_line_spread_m = std::max(opt.min_line_spread_m, node_options_.auto_min_line_spread_m);
  const CalibrationProblem pb(x, built.obs, prior_source_.priors(x), strict);
  const GeometryReport geo = checkReferenceGeometry(pb, strict);
  if (geo.status != CalibrationStatus::Ok) {
    spdlog::debug("calibrator: anchor {} not ready for automatic calibration: {}", x, geo.reason);
    waiting(geo.reason);
    return;
  }
  // With the strict spreads also in the calibration: references that pass the check only as
  // coplanar with stationary references off their plane must be calibrated as such (the side
  // decided by those references), not as a volume by the looser library spreads.
  calibrateAnchor(x, tr, std::move(built), true, &strict);
}
}  // namespace meshnav::calib
