#pragma once
/// @file cell_range_simulator.h
/// @brief The ranges of a fleet among many anchors in TDMA cells (`CellTdmaSchedule` over a
/// `GridAnchorLayout`): every slot, every active cell's seated device initiates one SDS-TWR range.
///
/// Per (slot, active cell), in ascending cell order, four draws are taken whether or not the seat
/// is used (so the pattern of one cell does not depend on who sits in another): u_drop, u_outlier,
/// n, u_excess; the range is z = β_ab d + γ_ab + σ_d n (+ the NLOS excess of `UwbRangeOptions` when
/// u_outlier < ε), dropped when u_drop < δ, d from the true positions at the slot time (tags:
/// p_IinG + R_ItoG p_TinI), stamped t + `time_offset_s`. A tag's cell is taken from its true
/// position at the phase's first slot (a real tag would use its estimate; the simulator uses the
/// truth). A vehicle ranges only within [0, its duration].
/// The schedule's **peer phase** (CellTdmaSchedule): tag `seat` of the fleet (id order) initiates
/// to the next other vehicle's tag, wherever in the hall it is, with draws of its own stream.
/// **Outage** (`CellOutage`): from t0 to t1 the anchors do not answer one vehicle's tags (slots
/// used, nothing written; counted), its tag-to-tag ranges go on.

#include <cstdint>
#include <map>
#include <vector>

#include "common/types.h"
#include "sim/cell_tdma_schedule.h"
#include "sim/grid_anchor_layout.h"
#include "sim/trajectory.h"
#include "sim/uwb_hardware_biases.h"
#include "sim/uwb_range_simulator.h"

namespace meshnav::sim {

/// One vehicle as the ranging sees it.
struct CellVehicle {
  const Trajectory* trajectory = nullptr;            ///< not owned
  std::map<SensorId, Eigen::Vector3d> tags_p_TinI;   ///< its tags' lever arms [m]
  double t_end_s = 0.0;                              ///< it ranges within [0, t_end_s] [s]
};

/// The anchors switched off for one vehicle (its tags hear none) over [t0_s, t1_s].
struct CellOutage {
  int vehicle = -1;  ///< −1: none
  double t0_s = 0.0, t1_s = 0.0;
  bool covers(size_t v, double t_s) const {
    return vehicle >= 0 && static_cast<size_t>(vehicle) == v && t_s >= t0_s && t_s <= t1_s;
  }
};

/// Per vehicle: what its tags initiated and what became of it.
struct CellRangeStats {
  int64_t tag_slots = 0;      ///< slots in which one of its tags was seated in a cell
  int64_t peer_slots = 0;     ///< peer-phase slots of its tags with the peer flying
  int64_t ranges = 0;         ///< written (to anchors and to other vehicles' tags)
  int64_t tag_to_tag = 0;     ///< of those, to another vehicle's tag
  int64_t dropped = 0;
  int64_t outliers = 0;
  int64_t outage_silent = 0;  ///< tag-to-anchor slots in its outage
  int64_t seat_waits = 0;     ///< phases one of its tags spent in an active cell without a seat
};

struct CellRanges {
  std::vector<std::vector<SimulatedRange>> vehicle;  ///< ranges each vehicle's tags initiated, in time order
  std::vector<SimulatedRange> mesh;                  ///< anchor-to-anchor, in time order
  std::vector<CellRangeStats> stats;                 ///< per vehicle
  int64_t slots = 0;                                 ///< global slots simulated
  int64_t mesh_dropped = 0, mesh_outliers = 0;
};

class CellRangeSimulator {
 public:
  /// `biases` must hold every pair of the anchors and the vehicles' tags. Throws
  /// std::invalid_argument for a vehicle without trajectory or tags, or more anchors in a cell
  /// than the schedule has anchor seats.
  CellRangeSimulator(const GridAnchorLayout& layout, std::vector<CellVehicle> vehicles, const UwbHardwareBiases& biases,
                     const UwbRangeOptions& uwb, const CellTdmaSchedule& schedule, uint64_t seed, CellOutage outage = {});

  /// Every slot with t ≤ t_end_s.
  CellRanges simulate(double t_end_s) const;

 private:
  const GridAnchorLayout& layout_;
  std::vector<CellVehicle> vehicles_;
  const UwbHardwareBiases& biases_;
  UwbRangeOptions uwb_;
  CellTdmaSchedule schedule_;
  uint64_t seed_;
  CellOutage outage_;
};

}  // namespace meshnav::sim
