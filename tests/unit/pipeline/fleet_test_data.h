#pragma once
/// @file fleet_test_data.h
/// @brief What the tests of a fleet's feeds build their vehicles from (test_fleet_calibrator_feed,
/// test_peer_range_feed, test_peer_range_relay): a vehicle's setup with the fleet's known
/// anchors, and a range.

#include <map>

#include "common/setup.h"
#include "common/types.h"

namespace meshnav::pipeline::test {

/// A vehicle with `tags` (id -> lever arm [m]) among the known anchors 101 (0, 0, 2), 102 (4, 0, 2)
/// and 103 (0, 4, 2).
inline SystemSetup vehicleSetup(std::map<SensorId, Eigen::Vector3d> tags) {
  SystemSetup s;
  s.rel_tag_positions = std::move(tags);
  s.abs_anchor_positions = {{101, {0, 0, 2}}, {102, {4, 0, 2}}, {103, {0, 4, 2}}};
  return s;
}

/// A 3 m range between `a` and `b` at `t` [s].
inline RangeSample range(double t, SensorId a, SensorId b) {
  RangeSample r;
  r.t = Timestamp::fromSec(t);
  r.id_initiator = a;
  r.id_responder = b;
  r.range_m = r.range_corr_m = 3.0;
  return r;
}

}  // namespace meshnav::pipeline::test
