/// @file scaled_fleet_simulation.cpp
/// @brief simulateScaledFleet: a grid of anchors in cells, N vehicles in their regions, cell TDMA.

#include "sim/scaled_fleet_simulation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <numbers>
#include <sstream>

#include "sim/paper_scenario.h"
#include "sim/random_stream.h"
#include "sim/scenario_simulator.h"
#include "sim/trajectory_factory.h"
#include "sim/uwb_hardware_biases.h"

namespace meshnav::sim {

namespace {

constexpr std::array<TrajectoryKind, 4> kKinds{TrajectoryKind::Spiral, TrajectoryKind::Figure8,
                                               TrajectoryKind::Lawnmower, TrajectoryKind::Helix};

/// A pair whose a-priori and true bias the files carry: one end a tag, or two anchors of
/// neighbouring cells.
bool canRange(const PairBias& b, const GridAnchorLayout& layout, const std::map<SensorId, int>& cell_of_anchor) {
  const auto a = cell_of_anchor.find(b.a), c = cell_of_anchor.find(b.b);
  if (a == cell_of_anchor.end() || c == cell_of_anchor.end()) return true;
  return layout.cells().neighbours(a->second, c->second);
}

void keepRangeable(std::vector<PairBias>& biases, const GridAnchorLayout& layout,
                   const std::map<SensorId, int>& cell_of_anchor) {
  biases.erase(std::remove_if(biases.begin(), biases.end(),
                              [&](const PairBias& b) { return !canRange(b, layout, cell_of_anchor); }),
               biases.end());
}

}  // namespace

Hall scaledFleetRegion(const Hall& hall, int k, int n_vehicles, double region_fraction, double theta0_rad) {
  const Eigen::Vector3d size = hall.size();
  Eigen::Vector3d centre = hall.center();
  if (n_vehicles > 1) {
    const double theta = theta0_rad + 2.0 * std::numbers::pi * k / n_vehicles;
    centre.x() += 0.2 * size.x() * std::cos(theta);
    centre.y() += 0.2 * size.y() * std::sin(theta);
  }
  const Eigen::Vector2d half(0.5 * region_fraction * size.x(), 0.5 * region_fraction * size.y());
  Hall region;
  for (int i = 0; i < 2; ++i) {
    const double lo = std::max(hall.min_m[i], std::min(centre[i] - half[i], hall.max_m[i] - 2.0 * half[i]));
    region.min_m[i] = lo;
    region.max_m[i] = std::min(hall.max_m[i], lo + 2.0 * half[i]);
  }
  region.min_m.z() = hall.min_m.z();
  region.max_m.z() = hall.max_m.z();
  return region;
}

ScaledFleet simulateScaledFleet(const ScaledFleetOptions& options) {
  options.validate();
  const uint64_t seed = options.base.seed;
  const Hall hall = Hall::ofSize(options.hallSize());
  std::set<SensorId> tag_ids;
  for (int k = 0; k < options.n_vehicles; ++k)
    for (SensorId t : {99, 100, 105}) tag_ids.insert(t + 1000 * k);
  const GridAnchorLayout layout(hall, options.n_anchors, options.flyByCount(), tag_ids, seed);
  std::map<SensorId, int> cell_of_anchor;
  for (const GridAnchor& a : layout.anchors()) cell_of_anchor[a.id] = a.cell;

  RandomStream rng(RandomStream::deriveSeed(seed, "scaled_fleet"));
  const double theta0 = rng.uniform(0.0, 2.0 * std::numbers::pi);
  const int first_kind = std::min(3, static_cast<int>(std::floor(rng.uniform(0.0, 4.0))));

  ScaledFleet fleet;
  std::vector<std::unique_ptr<Trajectory>> trajectories;
  std::vector<CellVehicle> ranging;
  std::vector<SensorId> devices;
  for (const GridAnchor& a : layout.anchors()) devices.push_back(a.id);
  std::vector<SimulationOptions> vehicle_options;
  const PaperScenario paper = PaperScenario::paper();
  for (int k = 0; k < options.n_vehicles; ++k) {
    SimulationOptions o = options.base;
    o.seed = seed + static_cast<uint64_t>(k);
    o.hall_size_m = options.hallSize();
    o.flight_region = scaledFleetRegion(hall, k, options.n_vehicles, options.region_fraction, theta0);
    o.trajectory_kind = kKinds[static_cast<size_t>((first_kind + k) % 4)];
    o.tag_id_offset = 1000 * k;
    o.n_tags = 2;
    o.mesh_ranges = false;
    o.validate();
    PaperScenario scenario = paper;
    scenario.tags_p_TinI.clear();
    for (SensorId t : {100, 105}) scenario.tags_p_TinI[t + o.tag_id_offset] = paper.tags_p_TinI.at(t);
    scenario.anchors_p_AinG = layout.positions();
    scenario.known_anchor_ids = layout.knownIds();
    scenario.hall_min_m = hall.min_m;
    scenario.hall_max_m = hall.max_m;
    fleet.vehicles.push_back(ScenarioSimulator(o, scenario).run());
    trajectories.push_back(makeTrajectory(o));
    CellVehicle v;
    v.trajectory = trajectories.back().get();
    v.tags_p_TinI = scenario.tags_p_TinI;
    const Dataset& ds = fleet.vehicles.back().dataset;
    v.t_end_s = ds.imu.empty() ? 0.0 : ds.imu.back().t.sec();
    ranging.push_back(v);
    for (const auto& [id, l] : scenario.tags_p_TinI) devices.push_back(id);
    fleet.regions.push_back(*o.flight_region);
    vehicle_options.push_back(o);
  }

  RandomStream rng_tdma(RandomStream::deriveSeed(seed, "cell_tdma_phase"));
  const double t0_s = std::round(rng_tdma.uniform(0.0, options.tdma.slot_s) * 1e6) * 1e-6;
  int n_fleet_tags = 0;
  for (const CellVehicle& v : ranging) n_fleet_tags += static_cast<int>(v.tags_p_TinI.size());
  const CellTdmaSchedule schedule(layout.cells().colourCount(), options.tdma, t0_s, n_fleet_tags);
  const UwbHardwareBiases biases(devices, options.base.hardware);
  double t_end = 0.0;
  for (const CellVehicle& v : ranging) t_end = std::max(t_end, v.t_end_s);
  const CellRanges ranges =
      CellRangeSimulator(layout, ranging, biases, options.base.uwb, schedule, seed, options.outage).simulate(t_end);
  fleet.range_stats = ranges.stats;

  double shortest = t_end;
  for (size_t k = 0; k < fleet.vehicles.size(); ++k) {
    SimulationResult& r = fleet.vehicles[k];
    shortest = std::min(shortest, ranging[k].t_end_s);
    r.ranges = ranges.vehicle[k];
    for (const SimulatedRange& m : ranges.mesh)
      if (m.sample.t.sec() <= ranging[k].t_end_s) r.ranges.push_back(m);
    std::stable_sort(r.ranges.begin(), r.ranges.end(),
                     [](const SimulatedRange& a, const SimulatedRange& b) { return a.sample.t < b.sample.t; });
    r.dataset.ranges.clear();
    for (const SimulatedRange& m : r.ranges) r.dataset.ranges.push_back(m.sample);
    keepRangeable(r.dataset.setup.pair_biases, layout, cell_of_anchor);
    keepRangeable(r.dataset.truth->pair_biases, layout, cell_of_anchor);
    const CellRangeStats& st = ranges.stats[k];
    r.stats.n_range_slots = st.tag_slots;
    r.stats.n_dropped = st.dropped;
    r.stats.n_outliers = st.outliers;
    auto& sc = r.dataset.truth->scalars;
    sc["n_range_slots"] = static_cast<double>(st.tag_slots);
    sc["n_ranges"] = static_cast<double>(r.dataset.ranges.size());
    sc["n_dropped"] = static_cast<double>(st.dropped);
    sc["n_outliers"] = static_cast<double>(st.outliers);
    sc["n_tag_to_tag"] = static_cast<double>(st.tag_to_tag);
    sc["n_seat_waits"] = static_cast<double>(st.seat_waits);
    sc["tdma_slot_s"] = options.tdma.slot_s;
    sc["tdma_t0_s"] = t0_s;
    sc["tdma_frame_s"] = schedule.frameDuration();
    sc["tdma_tag_rate_hz"] = schedule.tagRangeRateHz();
    sc["tdma_peer_rate_hz"] = schedule.peerRangeRateHz();
    sc["tdma_colours"] = schedule.colourCount();
    sc.erase("scenario_anchor_layout");
    sc["scenario_anchor_grid_x"] = layout.pointsX();
    sc["scenario_anchor_grid_y"] = layout.pointsY();
    sc["scenario_cells_x"] = layout.cells().cellsX();
    sc["scenario_cells_y"] = layout.cells().cellsY();
    sc["scenario_n_known_anchors"] = static_cast<double>(layout.knownIds().size());
    sc["scenario_n_unknown_anchors"] = options.flyByCount();
    sc["scenario_n_vehicles"] = options.n_vehicles;
    sc["scenario_vehicle"] = static_cast<double>(k);
    const char* axes[3] = {"x", "y", "z"};
    for (int i = 0; i < 3; ++i) {
      sc[std::string("scenario_region_min_") + axes[i] + "_m"] = fleet.regions[k].min_m[i];
      sc[std::string("scenario_region_max_") + axes[i] + "_m"] = fleet.regions[k].max_m[i];
    }
    if (options.outage.vehicle == static_cast<int>(k)) {
      sc["outage_t0_s"] = options.outage.t0_s;
      sc["outage_t1_s"] = options.outage.t1_s;
      sc["n_outage_silent"] = static_cast<double>(st.outage_silent);
    }
  }

  std::ostringstream csv;
  csv << "id,x_m,y_m,z_m,cell,cell_x,cell_y,mount,known\n";
  for (const GridAnchor& a : layout.anchors())
    csv << a.id << "," << a.p_AinG.x() << "," << a.p_AinG.y() << "," << a.p_AinG.z() << "," << a.cell << ","
        << layout.cells().indexX(a.cell) << "," << layout.cells().indexY(a.cell) << "," << toString(a.mount) << ","
        << (a.known ? 1 : 0) << "\n";
  fleet.layout_csv = csv.str();

  std::ostringstream mission;
  const double t1 = std::round(options.calibrate_at_fraction * shortest), t2 = std::round(options.calibrate_again_at_fraction * shortest);
  mission << "# Generated by meshnav_sim --vehicles " << options.n_vehicles << " --anchors " << options.n_anchors
          << " --seed " << seed << " (docs/scenarios.md, \"A hundred anchors in TDMA cells\").\n"
          << "# Every fly-by anchor is collected from the start from every vehicle's tags and calibrated at "
          << t1 << " s;\n# those refused then (too few ranges, geometry) are tried again at " << t2 << " s.\n"
          << "collect_at_start: true\nsteps:\n"
          << "  - {t: " << t1 << ", action: calibrate}\n"
          << "  - {t: " << t2 << ", action: calibrate}\n";
  fleet.mission_yaml = mission.str();

  std::ostringstream d;
  d << layout.toString() << "\n" << schedule.toString() << "\n";
  for (size_t k = 0; k < fleet.vehicles.size(); ++k) {
    const CellRangeStats& st = ranges.stats[k];
    const double dur = std::max(ranging[k].t_end_s, 1e-9);
    d << "v" << k << ": " << toString(vehicle_options[k].trajectory_kind) << " in x [" << fleet.regions[k].min_m.x()
      << ", " << fleet.regions[k].max_m.x() << "] y [" << fleet.regions[k].min_m.y() << ", "
      << fleet.regions[k].max_m.y() << "] m; its tags ranged " << st.ranges << " times (" << st.ranges / dur
      << " Hz; " << st.tag_to_tag << " to other vehicles' tags), " << st.dropped << " dropped, " << st.outliers
      << " outliers, " << st.seat_waits << " seat waits";
    if (options.outage.vehicle == static_cast<int>(k)) d << ", " << st.outage_silent << " slots unanswered in its outage";
    d << "\n";
  }
  d << "anchor mesh: " << ranges.mesh.size() << " ranges, " << ranges.mesh_dropped << " dropped\n";
  fleet.description = d.str();
  return fleet;
}

}  // namespace meshnav::sim
