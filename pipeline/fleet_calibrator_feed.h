#pragma once
/// @file fleet_calibrator_feed.h
/// @brief What the one calibrator of a fleet hears from the vehicles and says to each, the same in
/// one process (pipeline::Pipeline, `meshnav_run --fleet`) and over LCM (`calibrator --fleet`,
/// docs/fleet.md "The fleet's calibrator over LCM"). Free of LCM.
///
///  - **Tags**: every vehicle's tags, each with its vehicle (CalibratorNode places a tag's range
///    with that vehicle's pose history).
///  - **The anchors' mesh once**: every vehicle's data carry the anchor–anchor ranges it heard; the
///    same exchange (the same time stamp and pair) in several vehicles' data is one range, given to
///    the calibrator once (within 10 s; the others counted "mesh_range_from_another_vehicle").
///  - **Ranges between two vehicles' tags** are no calibrator input (counted
///    "inter_vehicle_range_not_for_calibrator" where `forCalibrator` is asked).
///  - **Anchor beliefs**: each vehicle's latest ANCHORS; towards the calibrator, per anchor the
///    covariance intersection of the vehicles' latest beliefs (AnchorBeliefIntersection: they all
///    start from the one ANCHOR_INIT and are correlated by an unknown amount).
///  - **ANCHOR_INIT** to vehicle v: without the pair biases of other vehicles' tags
///    (restrictToVehicle, fleet.h).
/// A single vehicle passes everything through unchanged.

#include <map>
#include <set>
#include <tuple>
#include <vector>

#include "common/diagnostics.h"
#include "common/messages.h"
#include "common/setup.h"
#include "common/types.h"
#include "pipeline/pipeline.h"

namespace meshnav::pipeline {

class FleetCalibratorFeed {
 public:
  /// `fleet_setup`: what the calibrator knows (mergeFleetSetups); counters go to `diag`, which must
  /// outlive the feed. Throws std::invalid_argument for an empty list or a vehicle's tag that is not
  /// a tag of `fleet_setup`.
  FleetCalibratorFeed(const std::vector<Vehicle>& vehicles, const SystemSetup& fleet_setup, Diagnostics& diag);

  size_t vehicleCount() const { return setups_.size(); }
  /// The vehicle index of every tag (CalibratorNode's `vehicle_of_tag`).
  const std::map<SensorId, size_t>& vehicleOfTag() const { return vehicle_of_tag_; }
  /// True when `r` joins tags of two different vehicles (an inter-vehicle range).
  bool betweenVehicles(const RangeSample& r) const;
  /// Whether the calibrator takes `r` (any vehicle's): false for an inter-vehicle range and for an
  /// anchor–anchor range another vehicle's data already gave it within 10 s (each counted).
  bool forCalibrator(const RangeSample& r);
  /// Vehicle `v`'s new ANCHORS; returns what the calibrator gets: per anchor the CI of every
  /// vehicle's latest belief (for one vehicle, `anchors` itself). Out of range v: std::out_of_range.
  std::vector<AnchorEstimate> anchorsFrom(size_t v, const std::vector<AnchorEstimate>& anchors);
  /// `a` as vehicle `v` may fuse it (restrictToVehicle; for one vehicle `a` itself).
  AnchorInit forVehicle(size_t v, const AnchorInit& a) const;

 private:
  std::vector<SystemSetup> setups_;
  SystemSetup fleet_setup_;
  Diagnostics& diag_;
  std::map<SensorId, size_t> vehicle_of_tag_;
  std::vector<std::map<SensorId, AnchorEstimate>> beliefs_;         ///< per vehicle, its latest ANCHORS
  std::set<std::tuple<int64_t, SensorId, SensorId>> mesh_ranges_;  ///< (µs, ids) given to the calibrator
};

}  // namespace meshnav::pipeline
