/// Tests of CalibratorNode on the simulated paper sequence (seed 1): fly-by calibration with
/// commands, refusals, automatic mode, out-of-order and bad input, waiting ranges, heartbeat.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <random>
#include <set>

#include <yaml-cpp/yaml.h>

#include "calibrator/node/calibrator_node.h"
#include "sim/scenario_simulator.h"

using namespace meshnav;
using namespace meshnav::calib;

namespace {

/// Seed 1 of the paper scenario, simulated once per test binary.
const sim::SimulationResult& seed1() {
  static const sim::SimulationResult res = [] {
    sim::SimulationOptions o;
    o.seed = 1;
    return sim::ScenarioSimulator(o).run();
  }();
  return res;
}

/// Ground truth as a small-covariance estimate (1 cm, 0.2°).
PoseEstimate asEstimate(const PoseSample& p) {
  PoseEstimate e;
  e.t = p.t;
  e.p_IinG = p.p_IinG;
  e.q_ItoG = p.q_ItoG;
  e.cov_p_m2 = 1e-4 * Eigen::Matrix3d::Identity();
  e.cov_theta_rad2 = std::pow(0.2 * M_PI / 180.0, 2) * Eigen::Matrix3d::Identity();
  return e;
}

CalibCommand command(CalibCommand::Action a, std::vector<SensorId> ids, double t_s = 0.0) {
  CalibCommand c;
  c.t = Timestamp::fromSec(t_s);
  c.action = a;
  c.anchors = std::move(ids);
  return c;
}

/// Everything a node emitted.
struct Outputs {
  std::vector<AnchorInit> inits;
  std::vector<CalibStatus> statuses;
};

CalibratorSinks sinksInto(Outputs& out) {
  CalibratorSinks s;
  s.anchor_init = [&out](const AnchorInit& a) { out.inits.push_back(a); };
  s.status = [&out](const CalibStatus& st) { out.statuses.push_back(st); };
  return s;
}

/// A command issued before the first input at or after `t_s`.
struct TimedCommand {
  double t_s;
  CalibCommand cmd;
};

/// Feeds ground-truth poses and ranges of `ds` in time order (poses first on equal times), with
/// `cmds` issued before the first input at or after their times (at the end of the data when none
/// is); stops before the first input after `t_end_s`. `pose_filter` may drop or alter poses.
/// Each pose goes to every vehicle of `vehicles` (the node's pose histories; one vehicle: 0).
void replay(CalibratorNode& node, const Dataset& ds, std::vector<TimedCommand> cmds,
            double t_end_s = std::numeric_limits<double>::infinity(),
            const std::function<bool(PoseEstimate&)>& pose_filter = {}, const std::vector<size_t>& vehicles = {0}) {
  size_t ip = 0, ir = 0, ic = 0;
  const auto& poses = ds.ground_truth;
  const auto& ranges = ds.ranges;
  while (ip < poses.size() || ir < ranges.size()) {
    const bool pose_next = ir >= ranges.size() || (ip < poses.size() && poses[ip].t <= ranges[ir].t);
    const Timestamp t = pose_next ? poses[ip].t : ranges[ir].t;
    if (t.sec() > t_end_s) return;  // commands not due yet are not issued
    while (ic < cmds.size() && t.sec() >= cmds[ic].t_s) {
      cmds[ic].cmd.t = t;
      node.onCommand(cmds[ic++].cmd);
    }
    if (pose_next) {
      PoseEstimate e = asEstimate(poses[ip++]);
      if (!pose_filter || pose_filter(e))
        for (size_t v : vehicles) node.onPose(e, v);
    } else {
      node.onRange(ranges[ir++]);
    }
  }
  while (ic < cmds.size()) node.onCommand(cmds[ic++].cmd);
}

/// Poses and ranges of seed 1 with from_s < t <= to_s.
Dataset slice(double from_s, double to_s) {
  Dataset d;
  for (const auto& p : seed1().dataset.ground_truth)
    if (p.t.sec() > from_s && p.t.sec() <= to_s) d.ground_truth.push_back(p);
  for (const auto& r : seed1().dataset.ranges)
    if (r.t.sec() > from_s && r.t.sec() <= to_s) d.ranges.push_back(r);
  return d;
}

double positionError(const AnchorInit& a) {
  return (a.p_AinG - seed1().dataset.truth->anchor_positions.at(a.id)).norm();
}

std::set<SensorId> refIds(const AnchorInit& a) {
  std::set<SensorId> ids;
  for (const auto& b : a.biases) {
    EXPECT_EQ(b.b, a.id);
    ids.insert(b.a);
  }
  return ids;
}

const CalibAnchorStatus* find(const CalibStatus& s, SensorId id) {
  for (const auto& a : s.anchors)
    if (a.id == id) return &a;
  return nullptr;
}

/// Copy of one anchor's entry in the node's current status (state "absent" when missing).
CalibAnchorStatus anchorStatus(const CalibratorNode& node, SensorId id) {
  const CalibStatus st = node.status();
  if (const auto* a = find(st, id)) return *a;
  CalibAnchorStatus none;
  none.id = id;
  none.state = "absent";
  return none;
}

const SystemSetup& setup() { return seed1().dataset.setup; }

}  // namespace

TEST(CalibratorNode, FlyByCalibratesAtEightyAndHundredSecondsWithCalibratedAnchorsAsReferences) {
  ASSERT_TRUE(seed1().dataset.truth.has_value());
  Outputs o;
  CalibratorNode node(CalibratorOptions{}, setup(), sinksInto(o));
  replay(node, seed1().dataset,
         {{80.0, command(CalibCommand::Action::Calibrate, {106, 107})},
          {100.0, command(CalibCommand::Action::Calibrate, {108, 109, 110})}});
  ASSERT_EQ(o.inits.size(), 5u);
  const std::set<SensorId> base{100, 101, 102, 103, 104, 105};
  for (size_t k = 0; k < 2; ++k) {
    const AnchorInit& a = o.inits[k];
    EXPECT_EQ(a.id, k == 0 ? 106 : 107);
    EXPECT_NEAR(a.t.sec(), 80.0, 0.05);
    std::printf("anchor %d at %.2f s: error %.3f m, sigma [%.3f %.3f %.3f] m, %d inliers, %d outliers\n", a.id,
                a.t.sec(), positionError(a), std::sqrt(a.cov_p_m2(0, 0)), std::sqrt(a.cov_p_m2(1, 1)),
                std::sqrt(a.cov_p_m2(2, 2)), a.n_inliers, a.n_outliers);
    EXPECT_LT(positionError(a), 0.3);
    const auto refs = refIds(a);
    for (SensorId r : base) EXPECT_TRUE(refs.count(r)) << "anchor " << a.id << " lacks a bias for " << r;
    EXPECT_GT(a.n_inliers, 300);
  }
  // 107 was calibrated after 106 in the same command: 106 is already its reference.
  EXPECT_TRUE(refIds(o.inits[1]).count(106));
  for (size_t k = 2; k < 5; ++k) {
    const AnchorInit& a = o.inits[k];
    EXPECT_EQ(a.id, static_cast<SensorId>(106 + k));
    EXPECT_NEAR(a.t.sec(), 100.0, 0.05);
    std::printf("anchor %d at %.2f s: error %.3f m, %d inliers, %d outliers, %zu refs\n", a.id, a.t.sec(),
                positionError(a), a.n_inliers, a.n_outliers, a.biases.size());
    EXPECT_LT(positionError(a), 0.3);
    const auto refs = refIds(a);
    for (SensorId r : base) EXPECT_TRUE(refs.count(r)) << "anchor " << a.id << " lacks a bias for " << r;
    EXPECT_TRUE(refs.count(106)) << a.id;
    EXPECT_TRUE(refs.count(107)) << a.id;
    for (SensorId earlier = 108; earlier < a.id; ++earlier) EXPECT_TRUE(refs.count(earlier)) << a.id;
    for (const auto& b : a.biases) {
      EXPECT_TRUE(std::isfinite(b.gamma_m));
      EXPECT_LT(std::abs(b.gamma_m), 1.0);
    }
  }
  const CalibStatus st = node.status();
  for (SensorId id : {106, 107, 108, 109, 110}) {
    ASSERT_NE(find(st, id), nullptr);
    EXPECT_EQ(find(st, id)->state, "calibrated");
  }
  EXPECT_EQ(st.counters.at("calibrations_ok"), 5);
  ASSERT_EQ(node.results().size(), 5u);  // what writeCalibrationYaml takes
  for (size_t k = 0; k < 5; ++k) {
    EXPECT_TRUE(node.results()[k].ok());
    EXPECT_EQ(node.results()[k].anchor_id, o.inits[k].id);
    EXPECT_EQ(node.results()[k].p_AinG, o.inits[k].p_AinG);
  }
  EXPECT_EQ(node.calibratedAnchors(), (std::vector<SensorId>{106, 107, 108, 109, 110}));
  // Ranges newer than the newest pose at the command waited (they were not dropped).
  EXPECT_EQ(st.counters.count("ranges_dropped_no_pose"), 0u);
}

TEST(CalibratorNode, EstimatorBeliefsReplaceTheCalibrationAsReferencePosition) {
  // Same flight twice; in the second the estimator reports 106/107 0.87 m off their calibration.
  auto run = [](bool with_beliefs) {
    Outputs out;
    CalibratorNode* self = nullptr;
    CalibratorSinks sinks = sinksInto(out);
    sinks.anchor_init = [&](const AnchorInit& a) {
      out.inits.push_back(a);
      if (!with_beliefs) return;
      std::vector<AnchorEstimate> beliefs;
      for (const auto& i : out.inits) {
        AnchorEstimate e;
        e.t = i.t;
        e.id = i.id;
        e.p_AinG = i.p_AinG + Eigen::Vector3d(0.5, 0.5, 0.5);
        e.cov_p_m2 = 0.01 * Eigen::Matrix3d::Identity();
        beliefs.push_back(e);
      }
      self->onAnchors(beliefs);
    };
    CalibratorNode node(CalibratorOptions{}, setup(), sinks);
    self = &node;
    replay(node, seed1().dataset,
           {{80.0, command(CalibCommand::Action::Calibrate, {106, 107})},
            {100.0, command(CalibCommand::Action::Calibrate, {108})}});
    return out.inits;
  };
  const auto plain = run(false), believed = run(true);
  ASSERT_EQ(plain.size(), 3u);
  ASSERT_EQ(believed.size(), 3u);
  auto gammaOf = [](const AnchorInit& a, SensorId ref) {
    for (const auto& b : a.biases)
      if (b.a == ref) return b.gamma_m;
    return std::numeric_limits<double>::quiet_NaN();
  };
  // 106 and 107 themselves are unaffected; 108's biases to them absorb the moved references.
  EXPECT_EQ(plain[0].p_AinG, believed[0].p_AinG);
  EXPECT_GT(std::abs(gammaOf(plain[2], 106) - gammaOf(believed[2], 106)), 0.05);
  EXPECT_GT(std::abs(gammaOf(plain[2], 107) - gammaOf(believed[2], 107)), 0.05);
}

TEST(CalibratorNode, RefusesEarlyWithAReasonAndKeepsCollecting) {
  Outputs out;
  CalibratorNodeOptions o;
  o.retry_refused = false;  // refused stays refused until the next command (the retry: next test)
  CalibratorNode node(CalibratorOptions{}, setup(), sinksInto(out), o);
  replay(node, seed1().dataset, {{10.0, command(CalibCommand::Action::Calibrate, {106})}}, 10.01);
  EXPECT_TRUE(out.inits.empty());
  ASSERT_FALSE(out.statuses.empty());
  const CalibStatus& st = out.statuses.back();  // published right after the command
  const auto* a = find(st, 106);
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->state, "refused");
  EXPECT_FALSE(a->reason.empty());
  std::printf("refusal at 10 s: %s\n", a->reason.c_str());
  EXPECT_EQ(st.counters.at("calibrations_refused"), 1);
  ASSERT_EQ(node.results().size(), 1u);
  EXPECT_EQ(node.results()[0].status, CalibrationStatus::DegenerateGeometry);
  const int64_t n_at_refusal = a->n_ranges;

  // Collecting goes on; a later command succeeds.
  Dataset rest;
  for (const auto& p : seed1().dataset.ground_truth)
    if (p.t.sec() > 10.01) rest.ground_truth.push_back(p);
  for (const auto& r : seed1().dataset.ranges)
    if (r.t.sec() > 10.01) rest.ranges.push_back(r);
  replay(node, rest, {{80.0, command(CalibCommand::Action::Calibrate, {106})}}, 79.99);
  EXPECT_TRUE(out.inits.empty());
  const CalibStatus st_later = node.status();
  const auto* later = find(st_later, 106);
  ASSERT_NE(later, nullptr);
  EXPECT_EQ(later->state, "refused");
  EXPECT_GT(later->n_ranges, n_at_refusal + 500);
  EXPECT_GE(later->n_refs, 6);
  Dataset tail;
  for (const auto& p : rest.ground_truth)
    if (p.t.sec() > 79.99) tail.ground_truth.push_back(p);
  for (const auto& r : rest.ranges)
    if (r.t.sec() > 79.99) tail.ranges.push_back(r);
  replay(node, tail, {{80.0, command(CalibCommand::Action::Calibrate, {106})}}, 80.01);
  ASSERT_EQ(out.inits.size(), 1u);
  EXPECT_LT(positionError(out.inits[0]), 0.3);
}

TEST(CalibratorNode, AutoModeCalibratesEveryUnknownAnchorByItself) {
  Outputs out;
  CalibratorNodeOptions no;
  no.auto_mode = true;
  CalibratorNode node(CalibratorOptions{}, setup(), sinksInto(out), no);
  replay(node, seed1().dataset, {});
  std::set<SensorId> ids;
  for (const auto& a : out.inits) {
    ids.insert(a.id);
    std::printf("auto: anchor %d at %.1f s: error %.3f m, %d inliers, %zu refs\n", a.id, a.t.sec(), positionError(a),
                a.n_inliers + a.n_outliers, a.biases.size());
    EXPECT_GE(a.n_inliers + a.n_outliers, no.auto_min_ranges);
    EXPECT_LT(positionError(a), 0.3) << a.id;
    EXPECT_GT(a.t.sec(), 5.0) << "not during take-off";
  }
  EXPECT_EQ(ids, (std::set<SensorId>{106, 107, 108, 109, 110}));
  EXPECT_EQ(out.inits.size(), 5u) << "each anchor once";

  // Without auto mode nothing happens by itself.
  Outputs manual;
  CalibratorNode quiet(CalibratorOptions{}, setup(), sinksInto(manual));
  replay(quiet, seed1().dataset, {}, 60.0);
  EXPECT_TRUE(manual.inits.empty());
}

TEST(CalibratorNode, EachTagIsPlacedWithItsOwnVehiclesPoseHistory) {
  // Seed 1's tags 100 and 105 as if they were on two vehicles of a fleet (vehicle 0 and 1).
  const std::vector<TimedCommand> cmds = {{80.0, command(CalibCommand::Action::Calibrate, {106, 107})}};
  const std::map<SensorId, size_t> fleet{{100, 0}, {105, 1}};
  Outputs single, both, only0;
  CalibratorNode one(CalibratorOptions{}, setup(), sinksInto(single));
  replay(one, seed1().dataset, cmds);
  // Both vehicles given the same (true) poses: the very same calibration as one vehicle.
  CalibratorNode two(CalibratorOptions{}, setup(), sinksInto(both), {}, fleet);
  EXPECT_EQ(two.vehicleCount(), 2u);
  replay(two, seed1().dataset, cmds, std::numeric_limits<double>::infinity(), {}, {0, 1});
  ASSERT_EQ(single.inits.size(), 2u);
  ASSERT_EQ(both.inits.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(both.inits[k].id, single.inits[k].id);
    EXPECT_LT((both.inits[k].p_AinG - single.inits[k].p_AinG).norm(), 1e-9) << both.inits[k].id;
    EXPECT_EQ(refIds(both.inits[k]), refIds(single.inits[k]));
  }
  EXPECT_EQ(two.poseHistorySize(), 2 * one.poseHistorySize());
  // Only vehicle 0 reports poses: 105's ranges have no pose to be placed with, 100's do.
  CalibratorNode lone(CalibratorOptions{}, setup(), sinksInto(only0), {}, fleet);
  replay(lone, seed1().dataset, cmds, std::numeric_limits<double>::infinity(), {}, {0});
  ASSERT_EQ(only0.inits.size(), 2u);
  for (const auto& a : only0.inits) {
    EXPECT_TRUE(refIds(a).count(100)) << a.id;
    EXPECT_FALSE(refIds(a).count(105)) << a.id << " has a bias for a tag whose vehicle sent no pose";
    EXPECT_LT(positionError(a), 0.3) << a.id;
  }
  const CalibStatus st = lone.status();
  EXPECT_GT(st.counters.at("ranges_waiting_for_pose"), 100) << "105's ranges wait for vehicle 1's poses";
  // A pose of a vehicle that carries no tag is bad input; a map naming a non-tag is refused.
  lone.onPose(asEstimate(seed1().dataset.ground_truth.back()), 2);
  EXPECT_EQ(lone.diagnostics().get("bad_pose"), 1);
  EXPECT_THROW(CalibratorNode(CalibratorOptions{}, setup(), {}, {}, {{101, 1}}), std::invalid_argument);
}

TEST(CalibratorNode, OutOfOrderPosesGiveTheSameResultAsInOrder) {
  auto run = [](bool shuffle) {
    Outputs out;
    CalibratorNode node(CalibratorOptions{}, setup(), sinksInto(out));
    // Poses arrive in bursts of 8 (a late, bursty estimator), each burst when its last pose is
    // due; with `shuffle` every burst comes in reverse order.
    std::vector<std::vector<PoseEstimate>> bursts;
    for (const auto& p : seed1().dataset.ground_truth) {
      if (bursts.empty() || bursts.back().size() == 8) bursts.emplace_back();
      bursts.back().push_back(asEstimate(p));
    }
    size_t ib = 0;
    bool sent = false;
    for (const auto& r : seed1().dataset.ranges) {
      if (r.t.sec() > 80.5) break;
      for (; ib < bursts.size() && bursts[ib].back().t <= r.t; ++ib) {
        auto burst = bursts[ib];
        if (shuffle) std::reverse(burst.begin(), burst.end());
        for (const auto& p : burst) node.onPose(p);
      }
      if (!sent && r.t.sec() >= 80.0) {
        node.onCommand(command(CalibCommand::Action::Calibrate, {106, 107}));
        sent = true;
      }
      node.onRange(r);
    }
    return std::make_pair(out.inits, node.diagnostics().get("poses_out_of_order"));
  };
  const auto [a, n_a] = run(false);
  const auto [b, n_b] = run(true);
  EXPECT_EQ(n_a, 0);
  EXPECT_GT(n_b, 1000);
  ASSERT_EQ(a.size(), 2u);
  ASSERT_EQ(b.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(a[k].id, b[k].id);
    EXPECT_LT((a[k].p_AinG - b[k].p_AinG).norm(), 1e-6);
    EXPECT_LT(positionError(b[k]), 0.3);
  }
}

TEST(CalibratorNode, PosesOlderThanTheWindowAreDroppedAndHistoryIsBounded) {
  CalibratorNodeOptions no;
  no.history_window_s = 20.0;
  CalibratorNode node(CalibratorOptions{}, setup(), {}, no);
  for (const auto& p : seed1().dataset.ground_truth) node.onPose(asEstimate(p));
  // 60 Hz ground truth: at most window + prune slack (10 s) of poses.
  EXPECT_LE(node.poseHistorySize(), static_cast<size_t>(60 * 31));
  EXPECT_GE(node.poseHistorySize(), static_cast<size_t>(60 * 19));
  const Timestamp newest = seed1().dataset.ground_truth.back().t;
  PoseEstimate old = asEstimate(seed1().dataset.ground_truth.front());
  old.t = newest - Duration::fromSec(25.0);  // beyond the 20 s window
  node.onPose(old);
  EXPECT_EQ(node.diagnostics().get("pose_too_old"), 1);
  // Far beyond the window and the time guard's offset: refused by the guard (issue 12).
  old.t = newest - Duration::fromSec(100.0);
  node.onPose(old);
  EXPECT_EQ(node.diagnostics().get("pose_too_old"), 1);
  EXPECT_EQ(node.diagnostics().get("POSE:time_behind"), 1);
}

TEST(CalibratorNode, RangesWithoutAPoseWaitUntilThePosesArrive) {
  Outputs out;
  CalibratorNode node(CalibratorOptions{}, setup(), sinksInto(out));
  // All ranges up to 80 s, but no pose yet (the estimator is late).
  for (const auto& r : seed1().dataset.ranges)
    if (r.t.sec() <= 80.0) node.onRange(r);
  node.onCommand(command(CalibCommand::Action::Calibrate, {106}, 80.0));
  EXPECT_TRUE(out.inits.empty());
  const CalibStatus st = node.status();
  EXPECT_GT(st.counters.at("ranges_waiting_for_pose"), 200);
  const auto* a = find(st, 106);
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->state, "refused");
  EXPECT_NE(a->reason.find("wait for a tag pose"), std::string::npos) << a->reason;
  // The poses arrive: the same ranges are now used.
  for (const auto& p : seed1().dataset.ground_truth)
    if (p.t.sec() <= 80.1) node.onPose(asEstimate(p));
  node.onCommand(command(CalibCommand::Action::Calibrate, {106}, 80.1));  // a new command
  ASSERT_EQ(out.inits.size(), 1u);
  EXPECT_LT(positionError(out.inits[0]), 0.3);
}

TEST(CalibratorNode, TagRangesInAPoseGapAreDroppedAndCounted) {
  Outputs out;
  CalibratorNode node(CalibratorOptions{}, setup(), sinksInto(out));
  // No poses between 30 and 40 s.
  replay(node, seed1().dataset, {{80.0, command(CalibCommand::Action::Calibrate, {106})}}, 80.01,
         [](PoseEstimate& p) { return p.t.sec() < 30.0 || p.t.sec() > 40.0; });
  ASSERT_EQ(out.inits.size(), 1u);
  EXPECT_LT(positionError(out.inits[0]), 0.3);
  // 10 s × 2 tags × ~2 ranges/s per pair.
  const int64_t dropped = node.diagnostics().get("ranges_dropped_no_pose");
  EXPECT_GT(dropped, 20);
  EXPECT_LT(dropped, 60);
}

TEST(CalibratorNode, BadInputIsCountedNeverUsed) {
  Outputs clean_out, dirty_out;
  CalibratorNode clean(CalibratorOptions{}, setup(), sinksInto(clean_out));
  CalibratorNode dirty(CalibratorOptions{}, setup(), sinksInto(dirty_out));
  const std::vector<TimedCommand> cmds{{80.0, command(CalibCommand::Action::Calibrate, {106, 107})}};
  replay(clean, seed1().dataset, cmds, 80.01);

  Dataset ds;
  ds.ground_truth = seed1().dataset.ground_truth;
  int n_bad = 0;
  for (const auto& r : seed1().dataset.ranges) {
    ds.ranges.push_back(r);
    if (r.id_initiator != 106 && r.id_responder != 106) continue;
    RangeSample bad = r;
    switch (n_bad++ % 5) {
      case 0: bad.range_m = std::numeric_limits<double>::quiet_NaN(); break;
      case 1: bad.range_m = 1e6; break;
      case 2: bad.id_initiator = 999, bad.type_initiator = UwbType::Tag; break;  // tag not in the setup
      case 3: bad.id_initiator = setup().imu_id; break;
      case 4: bad.id_responder = bad.id_initiator; break;
    }
    ds.ranges.push_back(bad);
  }
  int k = 0;  // every 100th pose carries a NaN
  replay(dirty, ds, cmds, 80.01, [&k](PoseEstimate& p) {
    if (++k % 100 == 0) p.p_IinG.x() = std::numeric_limits<double>::quiet_NaN();
    return true;
  });
  const auto& d = dirty.diagnostics();
  EXPECT_GT(d.get("bad_range"), 100);
  EXPECT_GT(d.get("unknown_device"), 100);
  EXPECT_GE(d.get("bad_pose"), 45);  // 80 s × 60 Hz / 100
  ASSERT_EQ(dirty_out.inits.size(), 2u);
  ASSERT_EQ(clean_out.inits.size(), 2u);
  // NaN poses are every 100th of 60 Hz: interpolation over a 33 ms gap instead of 17 ms; the
  // estimate moves by less than a millimetre.
  for (size_t k = 0; k < 2; ++k) EXPECT_LT((dirty_out.inits[k].p_AinG - clean_out.inits[k].p_AinG).norm(), 5e-3);
  const CalibStatus st = dirty.status();
  EXPECT_EQ(st.counters.at("bad_range"), d.get("bad_range"));

  // Malformed estimator beliefs and commands are reported, not applied.
  AnchorEstimate nan_belief;
  nan_belief.id = 106;
  nan_belief.p_AinG.x() = std::numeric_limits<double>::quiet_NaN();
  dirty.onAnchors({nan_belief});
  EXPECT_EQ(d.get("bad_anchor_estimate"), 1);
  dirty.onCommand(command(CalibCommand::Action::Calibrate, {101, 100, -3}));
  EXPECT_EQ(d.get("bad_command"), 3);
  CalibCommand weird = command(CalibCommand::Action::Collect, {});
  weird.action = static_cast<CalibCommand::Action>(42);
  dirty.onCommand(weird);
  EXPECT_EQ(d.get("bad_command"), 4);
}

TEST(CalibratorNode, CollectAndAbortControlWhatIsKept) {
  CalibratorNodeOptions no;
  no.collect_from_start = false;
  Outputs out;
  CalibratorNode node(CalibratorOptions{}, setup(), sinksInto(out), no);
  replay(node, seed1().dataset, {}, 20.0);
  auto st = node.status();
  ASSERT_NE(find(st, 106), nullptr);
  EXPECT_EQ(find(st, 106)->state, "idle");
  EXPECT_EQ(find(st, 106)->n_ranges, 0);
  EXPECT_GT(node.diagnostics().get("ranges_not_collecting"), 100);

  // Collect 106 only, from 20 s on.
  Dataset rest;
  for (const auto& p : seed1().dataset.ground_truth)
    if (p.t.sec() > 20.0) rest.ground_truth.push_back(p);
  for (const auto& r : seed1().dataset.ranges)
    if (r.t.sec() > 20.0 && r.t.sec() <= 30.0) rest.ranges.push_back(r);
  node.onCommand(command(CalibCommand::Action::Collect, {106}));
  replay(node, rest, {}, 30.0);
  st = node.status();
  EXPECT_EQ(find(st, 106)->state, "collecting");
  EXPECT_GT(find(st, 106)->n_ranges, 50);
  EXPECT_EQ(find(st, 106)->n_refs, 6);  // tags 100, 105, anchors 101-104 (107-110 not references)
  EXPECT_EQ(find(st, 107)->state, "idle");
  EXPECT_EQ(find(st, 107)->n_ranges, 0);

  // Calibrating an idle anchor is reported in its status, not attempted.
  node.onCommand(command(CalibCommand::Action::Calibrate, {107}));
  EXPECT_NE(anchorStatus(node, 107).reason.find("not collecting"), std::string::npos);
  EXPECT_EQ(node.diagnostics().get("calibrations_refused"), 0);

  // Abort drops the buffer; Collect (all) restarts every idle anchor and new ones.
  node.onCommand(command(CalibCommand::Action::Abort, {106}));
  EXPECT_EQ(anchorStatus(node, 106).state, "idle");
  EXPECT_EQ(anchorStatus(node, 106).n_ranges, 0);
  node.onCommand(command(CalibCommand::Action::Collect, {}));
  for (SensorId id : {106, 107, 108, 109, 110}) EXPECT_EQ(anchorStatus(node, id).state, "collecting") << id;
  EXPECT_TRUE(out.inits.empty());
}

TEST(CalibratorNode, CollectOnACalibratedAnchorForgetsItsCalibration) {
  Outputs out;
  CalibratorNode node(CalibratorOptions{}, setup(), sinksInto(out));
  replay(node, seed1().dataset, {{80.0, command(CalibCommand::Action::Calibrate, {106})}}, 80.01);
  ASSERT_EQ(out.inits.size(), 1u);
  EXPECT_EQ(anchorStatus(node, 106).state, "calibrated");
  node.onCommand(command(CalibCommand::Action::Calibrate, {106}));  // ignored: already calibrated
  EXPECT_EQ(out.inits.size(), 1u);
  node.onCommand(command(CalibCommand::Action::Collect, {106}));
  EXPECT_EQ(anchorStatus(node, 106).state, "collecting");
  EXPECT_EQ(anchorStatus(node, 106).n_ranges, 0);
  EXPECT_TRUE(node.calibratedAnchors().empty());
}

TEST(CalibratorNode, AResentCommandIsExecutedOnceAndNeverCalibratesAnAnchorTwice) {
  // The mission re-sends a command whose answer (CALIB_STATUS) is late, with its issue time; a
  // network may duplicate a datagram. Either way the calibrator executes the command once.
  Outputs out;
  CalibratorNode node(CalibratorOptions{}, setup(), sinksInto(out));
  const CalibCommand collect = command(CalibCommand::Action::Collect, {106}, 10.0);
  const CalibCommand calibrate = command(CalibCommand::Action::Calibrate, {106, 107}, 80.0);
  const CalibCommand abort = command(CalibCommand::Action::Abort, {108}, 80.0);
  replay(node, slice(-1.0, 10.0), {});
  node.onCommand(collect);
  replay(node, slice(10.0, 80.0), {});
  const int64_t collected = anchorStatus(node, 106).n_ranges;
  EXPECT_GT(collected, 300);
  node.onCommand(collect);  // the Collect again (its answer was late): the buffer stays
  EXPECT_EQ(anchorStatus(node, 106).n_ranges, collected);
  node.onCommand(calibrate);
  ASSERT_EQ(out.inits.size(), 2u);
  node.onCommand(abort);
  EXPECT_EQ(anchorStatus(node, 108).state, "idle");
  node.onCommand(command(CalibCommand::Action::Collect, {108}, 80.5));  // a later step
  // Late resends of all three: no calibration forgotten, none repeated, 108 not aborted again.
  for (int k = 0; k < 3; ++k) {
    node.onCommand(collect);
    node.onCommand(calibrate);
    node.onCommand(abort);
  }
  EXPECT_EQ(out.inits.size(), 2u);
  EXPECT_EQ(anchorStatus(node, 106).state, "calibrated");
  EXPECT_EQ(anchorStatus(node, 107).state, "calibrated");
  EXPECT_EQ(anchorStatus(node, 108).state, "collecting");
  EXPECT_EQ(node.diagnostics().get("CALIB_CMD:duplicate"), 10);
  EXPECT_EQ(node.diagnostics().get("calibrations_ok"), 2);
  EXPECT_EQ(node.diagnostics().get("calibrate_already_calibrated"), 0);
  // A new command (a new issue time) acts: Collect re-collects a calibrated anchor.
  node.onCommand(command(CalibCommand::Action::Collect, {106}, 81.0));
  EXPECT_EQ(anchorStatus(node, 106).state, "collecting");
}

TEST(CalibratorNode, StatusHeartbeatAtOneHertzOfDataTime) {
  Outputs out;
  CalibratorNode node(CalibratorOptions{}, setup(), sinksInto(out));
  replay(node, seed1().dataset, {}, 60.0);
  // One status per second of data time from the first input on (0..60 s): 60 or 61.
  EXPECT_GE(out.statuses.size(), 60u);
  EXPECT_LE(out.statuses.size(), 61u);
  for (size_t k = 1; k < out.statuses.size(); ++k) {
    const double dt = (out.statuses[k].t - out.statuses[k - 1].t).sec();
    EXPECT_GT(dt, 0.9);
    EXPECT_LT(dt, 1.1);
  }
  const CalibStatus& last = out.statuses.back();
  EXPECT_EQ(last.anchors.size(), 5u);
  for (const auto& a : last.anchors) {
    EXPECT_EQ(a.state, "collecting");
    EXPECT_GT(a.n_ranges, 300);
  }
  EXPECT_GT(last.counters.at("ranges_kept"), 1000);
  EXPECT_GT(last.counters.at("ranges_not_needed"), 100);  // tag-known anchor ranges, tag-tag
  // tick() drives it without inputs; a jump emits one status, time going back emits none.
  const size_t n = out.statuses.size();
  const Timestamp t_jump = last.t + Duration::fromSec(5.0);
  node.tick(t_jump);
  ASSERT_EQ(out.statuses.size(), n + 1);
  EXPECT_EQ(out.statuses.back().t, t_jump);
  node.tick(t_jump - Duration::fromSec(1.0));
  EXPECT_EQ(out.statuses.size(), n + 1);
  node.tick(t_jump + Duration::fromSec(0.5));
  EXPECT_EQ(out.statuses.size(), n + 1);
  node.tick(t_jump + Duration::fromSec(1.0));
  EXPECT_EQ(out.statuses.size(), n + 2);
}

TEST(CalibratorNode, FarStampedInputsAreRefusedAndChangeNothing) {
  // Issue 12, finding 1: a RANGE or POSE stamped +1 h (or random bytes decoding to any utime) must
  // not move the data time; the calibration comes out exactly as without it.
  const auto cmds = std::vector<TimedCommand>{{80.0, command(CalibCommand::Action::Calibrate, {106})}};
  Outputs clean_out, out;
  CalibratorNode clean(CalibratorOptions{}, setup(), sinksInto(clean_out));
  replay(clean, seed1().dataset, cmds, 80.0);
  CalibratorNode node(CalibratorOptions{}, setup(), sinksInto(out));
  bool injected = false;
  replay(node, seed1().dataset, cmds, 80.0, [&](PoseEstimate& p) {
    if (injected || p.t.sec() < 30.0) return true;
    injected = true;
    const Timestamp future = p.t + Duration::fromSec(3600.0);
    RangeSample r = seed1().dataset.ranges.front();
    r.t = future;
    node.onRange(r);
    PoseEstimate q = p;
    q.t = future;
    node.onPose(q);
    node.tick(future);
    r.t = Timestamp{INT64_MIN};
    node.onRange(r);
    return true;
  });
  ASSERT_TRUE(injected);
  EXPECT_EQ(node.diagnostics().get("RANGE:time_ahead"), 1);
  EXPECT_EQ(node.diagnostics().get("RANGE:time_behind"), 1);
  EXPECT_EQ(node.diagnostics().get("POSE:time_ahead"), 1);
  EXPECT_EQ(node.diagnostics().get("tick:time_ahead"), 1);
  EXPECT_EQ(node.dataTime(), clean.dataTime());
  ASSERT_EQ(clean_out.inits.size(), 1u);
  ASSERT_EQ(out.inits.size(), 1u);
  EXPECT_EQ(out.inits[0].p_AinG, clean_out.inits[0].p_AinG);
  EXPECT_EQ(out.inits[0].t, clean_out.inits[0].t);
  EXPECT_EQ(out.statuses.size(), clean_out.statuses.size());
}

TEST(CalibratorNode, DuplicatedRangesAreCollectedOnce) {
  // Issue 12: a network that duplicates datagrams must not weigh those ranges twice.
  const auto cmds = std::vector<TimedCommand>{{80.0, command(CalibCommand::Action::Calibrate, {106, 107})}};
  Outputs clean_out, out;
  CalibratorNode clean(CalibratorOptions{}, setup(), sinksInto(clean_out));
  replay(clean, seed1().dataset, cmds, 80.0);
  Dataset dup = seed1().dataset;
  dup.ranges.clear();
  int64_t n_dup = 0;
  const auto& ranges = seed1().dataset.ranges;
  for (size_t i = 0; i < ranges.size(); ++i) {
    dup.ranges.push_back(ranges[i]);
    if (i % 20 == 7 && ranges[i].t.sec() <= 80.0) {  // 5 %: at once, or again 3 ranges later
      if (i % 40 == 7) {
        dup.ranges.push_back(ranges[i]);
      } else if (i >= 3) {
        dup.ranges.push_back(ranges[i - 3]);
      }
      ++n_dup;
    }
  }
  CalibratorNode node(CalibratorOptions{}, setup(), sinksInto(out));
  replay(node, dup, cmds, 80.0);
  EXPECT_EQ(node.diagnostics().get("RANGE:duplicate"), n_dup);
  EXPECT_GT(n_dup, 300);
  ASSERT_EQ(clean_out.inits.size(), 2u);
  ASSERT_EQ(out.inits.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(out.inits[k].p_AinG, clean_out.inits[k].p_AinG);
    EXPECT_EQ(out.inits[k].n_inliers, clean_out.inits[k].n_inliers);
  }
}

TEST(CalibratorNodeOptions, YamlRejectsUnknownKeysAndBadValues) {
  const auto ok = CalibratorNodeOptions::fromYaml(YAML::Load("{auto_mode: true, auto_min_ranges: 500}"), "x.yaml");
  EXPECT_TRUE(ok.auto_mode);
  EXPECT_EQ(ok.auto_min_ranges, 500);
  EXPECT_NE(ok.toString().find("auto_min_ranges: 500"), std::string::npos);
  try {
    CalibratorNodeOptions::fromYaml(YAML::Load("{auto_mod: true}"), "x.yaml");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("x.yaml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("calibrator_node.auto_mod"), std::string::npos);
  }
  EXPECT_THROW(CalibratorNodeOptions::fromYaml(YAML::Load("{status_period: -1}"), "x.yaml"), std::runtime_error);
  EXPECT_THROW(CalibratorNodeOptions::fromYaml(YAML::Load("{auto_min_ranges: many}"), "x.yaml"), std::runtime_error);
  CalibratorNodeOptions bad;
  bad.history_window_s = 0;
  EXPECT_THROW(CalibratorNode(CalibratorOptions{}, setup(), {}, bad), std::invalid_argument);
}

TEST(CalibratorNode, ARefusedAnchorIsRetriedWhenNewDataMakesItPass) {
  // Issue 12: a refusal (too early, too coplanar, a restarted calibrator short of data) used to be
  // final until the next Calibrate command. With retry_refused the anchor keeps collecting and is
  // calibrated by the automatic criterion once the data suffices.
  Outputs out;
  CalibratorNode node(CalibratorOptions{}, setup(), sinksInto(out));  // retry_refused: the default
  replay(node, seed1().dataset, {{10.0, command(CalibCommand::Action::Calibrate, {106})}}, 79.99);
  ASSERT_EQ(node.results().size(), 2u);
  EXPECT_EQ(node.results()[0].status, CalibrationStatus::DegenerateGeometry);  // at 10 s
  EXPECT_EQ(node.results()[1].status, CalibrationStatus::Ok);                 // retried later
  EXPECT_GE(node.results()[1].t.sec(), 20.0);  // not before auto_retry_period after the refusal
  ASSERT_EQ(out.inits.size(), 1u);
  EXPECT_LT(positionError(out.inits[0]), 0.3);
  const CalibStatus st = node.status();
  const auto* a = find(st, 106);
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->state, "calibrated");
  // Anchors that were never refused are not calibrated by it (no auto_mode): 107 still collects.
  const auto* b = find(st, 107);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->state, "collecting");
}

// A hand-held walk (tags within about 0.1 m of one plane) among wall anchors: automatic mode
// calibrates the unknown anchors the known ones off that plane tell the side of, and never one on
// the mirror side; the others say what they wait for or why they were refused.
TEST(CalibratorNode, AutoModeOnAWalkCalibratesOnTheRightSideOfTheTagPlaneOrSaysWhy) {
  sim::SimulationOptions o;
  o.seed = 3;
  o.trajectory_kind = sim::TrajectoryKind::Walk;
  o.anchor_layout = sim::AnchorLayoutKind::Walls;
  o.hall_size_m = Eigen::Vector3d(10.0, 9.0, 5.0);
  o.n_tags = 1;
  o.n_known_anchors = 4;
  o.n_unknown_anchors = 4;
  o.duration_s = 80.0;
  const sim::SimulationResult walk = sim::ScenarioSimulator(o).run();
  Outputs out;
  CalibratorNodeOptions no;
  no.auto_mode = true;
  CalibratorNode node(CalibratorOptions{}, walk.dataset.setup, sinksInto(out), no);
  replay(node, walk.dataset, {});
  for (const auto& a : out.inits) {
    const double err = (a.p_AinG - walk.dataset.truth->anchor_positions.at(a.id)).norm();
    std::printf("walk: anchor %d at %.1f s: error %.3f m, z %.2f m (true %.2f m)\n", a.id, a.t.sec(), err,
                a.p_AinG.z(), walk.dataset.truth->anchor_positions.at(a.id).z());
    EXPECT_LT(err, 0.4) << a.id;
  }
  EXPECT_GE(out.inits.size(), 2u) << "a walk among anchors at several heights calibrates some anchors";
  for (const auto& a : node.status().anchors) {
    if (a.state == "calibrated") continue;
    std::printf("walk: anchor %d %s: %s\n", a.id, a.state.c_str(), a.reason.c_str());
    EXPECT_FALSE(a.reason.empty()) << a.id;
  }
  // Before the mirror check, automatic mode calibrated nothing from a walk.
  CalibratorOptions no_mirror;
  no_mirror.mirror_reference_min_offset_m = 0.0;
  Outputs old;
  CalibratorNode old_node(no_mirror, walk.dataset.setup, sinksInto(old), no);
  replay(old_node, walk.dataset, {});
  EXPECT_TRUE(old.inits.empty());
  EXPECT_NE(anchorStatus(old_node, walk.dataset.truth->anchor_positions.rbegin()->first).reason.find("coplanar"),
            std::string::npos);
}

TEST(CalibratorOptions, NumbersOutOfRangeAreRefusedNamingFileAndKey) {
  // Found by an audit: max_pose_gap 1e13 loaded and threw std::out_of_range at the first
  // calibration without naming the key; a negative max_pose_gap gave no tag range a pose.
  EXPECT_NO_THROW(CalibratorOptions::fromYaml(YAML::Load("{max_pose_gap: 0.2, min_measurements: 12}"), "c.yaml"));
  const std::pair<const char*, const char*> cases[] = {
      {"{max_pose_gap: 1e13}", "calibrator.max_pose_gap"},
      {"{max_pose_gap: -0.5}", "calibrator.max_pose_gap"},
      {"{lm_max_iterations: 0}", "calibrator.lm_max_iterations"},
      {"{min_measurements: -1}", "calibrator.min_measurements"},
      {"{correlated_reference_fraction: 1.5}", "calibrator.correlated_reference_fraction"},
      {"{min_tag_position_sigma: -0.1}", "calibrator.min_tag_position_sigma"},
  };
  for (const auto& [text, key] : cases) {
    try {
      CalibratorOptions::fromYaml(YAML::Load(text), "c.yaml");
      ADD_FAILURE() << "accepted " << text;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("c.yaml"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}
