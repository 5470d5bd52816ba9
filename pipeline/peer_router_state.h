#pragma once
/// @file peer_router_state.h
/// @brief The peer_router's restart journal (docs/formats.md "peer_router_state.yaml"): whose
/// information each vehicle's estimate holds (PeerRangeRouter::Provenance), so that a respawned
/// router keeps the inter-vehicle flow acyclic (docs/decisions/016-fleet-sharing.md) instead of
/// starting from "nobody holds anything" and sending a vehicle's information back to it.
///
/// ```yaml
/// layout: 1
/// t_us: 63250000        # data time of the newest range or POSE when written [µs]
/// holds:                # vehicle -> {vehicle whose information it absorbed: data time it entered [µs]}
///   v0: {v1: 61250000}
///   v1: {}
/// ```
/// Vehicles by their fleet names: a journal of another fleet is refused naming the file and the
/// key. What is lost in a restart: what entered the provenance after the last write (at most the
/// process's --state-period of data time, 0.1 s); the router routes nothing while it is down.

#include <string>
#include <vector>

#include "common/types.h"
#include "pipeline/peer_range_router.h"

namespace meshnav::pipeline {

struct PeerRouterState {
  Timestamp t;                            ///< data time of the newest input when written
  PeerRangeRouter::Provenance provenance;  ///< by vehicle index of the fleet file
};

/// Writes `state` to `path` atomically (temporary file, rename), vehicles named by `names` (the
/// fleet's, by index). Throws std::runtime_error when it cannot be written.
void writePeerRouterState(const std::string& path, const PeerRouterState& state, const std::vector<std::string>& names);

/// Reads `path` for the fleet of `names`. Throws std::runtime_error "<path>: key '<k>' ..." for an
/// unknown key or vehicle, a missing or bad value, another layout; "<path>: cannot read" when absent.
PeerRouterState readPeerRouterState(const std::string& path, const std::vector<std::string>& names);

}  // namespace meshnav::pipeline
