/// @file cell_range_simulator.cpp
/// @brief CellRangeSimulator: slot by slot over the active cells of each phase.

#include "sim/cell_range_simulator.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "sim/random_stream.h"

namespace meshnav::sim {

namespace {

/// A tag of the fleet.
struct FleetTag {
  SensorId id = 0;
  size_t vehicle = 0;
  Eigen::Vector3d p_TinI = Eigen::Vector3d::Zero();
};

/// The fixed draws of one (slot, cell).
struct SlotDraws {
  double u_drop = 0.0, u_outlier = 0.0, n = 0.0, u_excess = 0.0;
};

}  // namespace

CellRangeSimulator::CellRangeSimulator(const GridAnchorLayout& layout, std::vector<CellVehicle> vehicles,
                                       const UwbHardwareBiases& biases, const UwbRangeOptions& uwb,
                                       const CellTdmaSchedule& schedule, uint64_t seed, CellOutage outage)
    : layout_(layout),
      vehicles_(std::move(vehicles)),
      biases_(biases),
      uwb_(uwb),
      schedule_(schedule),
      seed_(seed),
      outage_(outage) {
  for (const CellVehicle& v : vehicles_)
    if (!v.trajectory || v.tags_p_TinI.empty())
      throw std::invalid_argument("CellRangeSimulator: every vehicle needs a trajectory and a tag");
  if (layout_.maxAnchorsPerCell() > schedule_.options().anchor_seats)
    throw std::invalid_argument("CellRangeSimulator: a cell has more anchors than the schedule has anchor seats");
  if (schedule_.colourCount() != layout_.cells().colourCount())
    throw std::invalid_argument("CellRangeSimulator: the schedule's phases are not the cells' colours");
}

CellRanges CellRangeSimulator::simulate(double t_end_s) const {
  const CellGrid& cells = layout_.cells();
  const std::map<SensorId, Eigen::Vector3d> anchors = layout_.positions();
  std::vector<FleetTag> tags;
  for (size_t v = 0; v < vehicles_.size(); ++v)
    for (const auto& [id, l] : vehicles_[v].tags_p_TinI) tags.push_back({id, v, l});
  std::sort(tags.begin(), tags.end(), [](const FleetTag& a, const FleetTag& b) { return a.id < b.id; });
  std::map<SensorId, size_t> tag_index;
  for (size_t i = 0; i < tags.size(); ++i) tag_index[tags[i].id] = i;

  std::vector<std::vector<int>> colour_cells(static_cast<size_t>(cells.colourCount()));
  for (int c = 0; c < cells.colourCount(); ++c) colour_cells[static_cast<size_t>(c)] = cells.cellsOfColour(c);
  std::vector<std::vector<SensorId>> near(static_cast<size_t>(cells.cellCount()));
  for (int c = 0; c < cells.cellCount(); ++c) near[static_cast<size_t>(c)] = layout_.anchorsNear(c);
  std::map<SensorId, std::vector<SensorId>> anchor_peers;  // an anchor's round robin: its neighbourhood but itself
  std::map<SensorId, int64_t> anchor_turn;
  for (const GridAnchor& a : layout_.anchors()) {
    auto& peers = anchor_peers[a.id];
    for (SensorId b : near[static_cast<size_t>(a.cell)])
      if (b != a.id) peers.push_back(b);
    anchor_turn[a.id] = 0;
  }

  if (schedule_.hasPeerPhase() && schedule_.peerPhaseSlots() != static_cast<int>(tags.size()) * schedule_.options().peer_slots)
    throw std::invalid_argument("CellRangeSimulator: the schedule's peer phase is not for the fleet's " +
                                std::to_string(tags.size()) + " tags");
  // The peer phase's round robin of each tag: the other vehicles' tags, in id order.
  std::vector<std::vector<size_t>> fleet_peers(tags.size());
  for (size_t i = 0; i < tags.size(); ++i)
    for (size_t j = 0; j < tags.size(); ++j)
      if (tags[j].vehicle != tags[i].vehicle) fleet_peers[i].push_back(j);
  std::vector<int64_t> peer_turn(tags.size(), 0);
  RandomStream rng_peer(RandomStream::deriveSeed(seed_, "cell_peer_ranges"));

  CellRanges out;
  out.vehicle.resize(vehicles_.size());
  out.stats.resize(vehicles_.size());
  std::vector<std::vector<size_t>> seats(static_cast<size_t>(cells.cellCount()));  // tag indices per cell
  std::vector<std::vector<SensorId>> tag_peers(tags.size());
  std::vector<int64_t> tag_turn(tags.size(), 0);
  std::vector<int> tag_cell(tags.size(), -1);
  RandomStream rng(RandomStream::deriveSeed(seed_, "cell_ranges"));

  auto tagPosition = [&](const FleetTag& tag, double t) {
    const TrajectoryState st = vehicles_[tag.vehicle].trajectory->evaluate(t);
    return Eigen::Vector3d(st.p_IinG + st.R_ItoG * tag.p_TinI);
  };
  auto ranging = [&](size_t v, double t) { return t >= 0.0 && t <= vehicles_[v].t_end_s; };
  auto position = [&](SensorId id, double t) -> Eigen::Vector3d {
    if (const auto it = tag_index.find(id); it != tag_index.end()) return tagPosition(tags[it->second], t);
    return anchors.at(id);
  };
  // One exchange: nullopt when dropped or stamped before 0.
  auto exchange = [&](SensorId a, SensorId b, UwbType type_a, UwbType type_b, double t, const SlotDraws& u,
                      int64_t& dropped, int64_t& outliers) -> std::optional<SimulatedRange> {
    if (u.u_drop < uwb_.drop_fraction) {
      ++dropped;
      return std::nullopt;
    }
    const double stamp_s = t + uwb_.time_offset_s;
    if (stamp_s < 0.0) return std::nullopt;
    const double excess = uwb_.nlos_excess == "exponential"
                              ? uwb_.outlier_min_m - uwb_.outlier_mean_m * std::log1p(-u.u_excess)
                              : uwb_.outlier_min_m + (uwb_.outlier_max_m - uwb_.outlier_min_m) * u.u_excess;
    const double d = (position(a, t) - position(b, t)).norm();
    const PairBias& bias = biases_.truth(a, b);
    SimulatedRange r;
    r.true_distance_m = d;
    r.outlier = u.u_outlier < uwb_.outlier_fraction;
    double z = bias.beta * d + bias.gamma_m + uwb_.sigma_range_m * u.n;
    if (r.outlier) {
      z += excess;
      ++outliers;
    }
    r.sample.t = Timestamp::fromSec(stamp_s);
    r.sample.id_initiator = a;
    r.sample.id_responder = b;
    r.sample.type_initiator = type_a;
    r.sample.type_responder = type_b;
    r.sample.range_m = r.sample.range_corr_m = z;
    r.sample.R_m2 = uwb_.sigma_range_m * uwb_.sigma_range_m;
    r.sample.los = true;
    return r;
  };

  const int64_t n_slots = schedule_.slotCountUntil(t_end_s);
  for (int64_t s = 0; s < n_slots; ++s) {
    const CellTdmaSlot slot = schedule_.slot(s);
    if (slot.role == CellSlotRole::PeerSeat) {
      // Fleet-wide: tag `seat` initiates to the next other vehicle's tag (its own draws, so the cells'
      // draws do not depend on the peer phase).
      SlotDraws u;
      u.u_drop = rng_peer.uniform();
      u.u_outlier = rng_peer.uniform();
      u.n = rng_peer.gaussian();
      u.u_excess = rng_peer.uniform();
      const size_t i = static_cast<size_t>(slot.seat);
      const size_t v = tags[i].vehicle;
      const auto& peers = fleet_peers[i];
      if (!ranging(v, slot.t_s) || peers.empty()) continue;
      const size_t j = peers[static_cast<size_t>(peer_turn[i]++ % static_cast<int64_t>(peers.size()))];
      if (!ranging(tags[j].vehicle, slot.t_s)) continue;
      CellRangeStats& st = out.stats[v];
      ++st.peer_slots;
      if (auto r = exchange(tags[i].id, tags[j].id, UwbType::Tag, UwbType::Tag, slot.t_s, u, st.dropped, st.outliers)) {
        ++st.ranges;
        ++st.tag_to_tag;
        out.vehicle[v].push_back(*r);
      }
      continue;
    }
    const auto& active = colour_cells[static_cast<size_t>(slot.colour)];
    if (slot.phase_slot == 0) {  // seat the tags in the active cells
      for (size_t i = 0; i < tags.size(); ++i)
        tag_cell[i] = ranging(tags[i].vehicle, slot.t_s) ? cells.cellOf(tagPosition(tags[i], slot.t_s)) : -1;
      for (int c : active) seats[static_cast<size_t>(c)].clear();
      for (size_t i = 0; i < tags.size(); ++i) {
        if (tag_cell[i] < 0 || cells.colour(tag_cell[i]) != slot.colour) continue;
        auto& seated = seats[static_cast<size_t>(tag_cell[i])];
        if (static_cast<int>(seated.size()) >= schedule_.options().tag_seats) {
          ++out.stats[tags[i].vehicle].seat_waits;
          continue;
        }
        seated.push_back(i);
        auto& peers = tag_peers[i];
        peers = near[static_cast<size_t>(tag_cell[i])];
        if (!schedule_.hasPeerPhase())  // the other vehicles' tags of the neighbourhood join the round robin
          for (size_t j = 0; j < tags.size(); ++j)
            if (tags[j].vehicle != tags[i].vehicle && tag_cell[j] >= 0 && cells.neighbours(tag_cell[i], tag_cell[j]))
              peers.push_back(tags[j].id);
        std::sort(peers.begin(), peers.end());
      }
    }
    for (int c : active) {
      SlotDraws u;
      u.u_drop = rng.uniform();
      u.u_outlier = rng.uniform();
      u.n = rng.gaussian();
      u.u_excess = rng.uniform();
      if (slot.role == CellSlotRole::TagSeat) {
        const auto& seated = seats[static_cast<size_t>(c)];
        if (slot.seat >= static_cast<int>(seated.size())) continue;
        const size_t i = seated[static_cast<size_t>(slot.seat)];
        const size_t v = tags[i].vehicle;
        if (!ranging(v, slot.t_s)) continue;
        CellRangeStats& st = out.stats[v];
        ++st.tag_slots;
        const auto& peers = tag_peers[i];
        if (peers.empty()) continue;
        const SensorId b = peers[static_cast<size_t>(tag_turn[i]++ % static_cast<int64_t>(peers.size()))];
        const auto peer_tag = tag_index.find(b);
        const bool to_tag = peer_tag != tag_index.end();
        if (to_tag && !ranging(tags[peer_tag->second].vehicle, slot.t_s)) continue;
        if (!to_tag && outage_.covers(v, slot.t_s)) {
          ++st.outage_silent;
          continue;
        }
        if (auto r = exchange(tags[i].id, b, UwbType::Tag, to_tag ? UwbType::Tag : UwbType::Anchor, slot.t_s, u,
                              st.dropped, st.outliers)) {
          ++st.ranges;
          if (to_tag) ++st.tag_to_tag;
          out.vehicle[v].push_back(*r);
        }
      } else {
        const auto& own = layout_.anchorsOfCell(c);
        if (slot.seat >= static_cast<int>(own.size())) continue;
        const SensorId a = own[static_cast<size_t>(slot.seat)];
        const auto& peers = anchor_peers.at(a);
        if (peers.empty()) continue;
        const SensorId b = peers[static_cast<size_t>(anchor_turn[a]++ % static_cast<int64_t>(peers.size()))];
        if (auto r = exchange(a, b, UwbType::Anchor, UwbType::Anchor, slot.t_s, u, out.mesh_dropped, out.mesh_outliers))
          out.mesh.push_back(*r);
      }
    }
  }
  out.slots = n_slots;
  return out;
}

}  // namespace meshnav::sim
