/// EstimatorNode: initialization, estimation on synthetic data, bad input, outputs, run-time instances.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>

#include "common/pose_interpolation.h"
#include "node_test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

double orientationErrorDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return so3::logMap(a.conjugate() * b).norm() * 180.0 / M_PI;
}

}  // namespace

TEST(EstimatorNode, NoPropagationOrOutputBeforeInitialization) {
  synthetic::SyntheticOptions o;
  o.duration_s = 5.0;
  const Dataset ds = synthetic::makeSyntheticDataset(o);
  int poses = 0;
  EstimatorSinks sinks;
  sinks.pose = [&](const PoseEstimate&) { ++poses; };
  EstimatorNode node(test::testOptions(), ds.setup, sinks);
  for (const auto& s : ds.imu) {
    if (s.t.sec() >= 0.5) break;  // less than init.duration_s of landed data
    node.onImu(s);
  }
  EXPECT_FALSE(node.initialized());
  EXPECT_FALSE(node.pose().has_value());
  EXPECT_EQ(poses, 0);
}

TEST(EstimatorNode, NoiseFreeRunTracksTruth) {
  synthetic::SyntheticOptions o;
  o.duration_s = 20.0;
  const Dataset ds = synthetic::makeSyntheticDataset(o);
  std::vector<PoseEstimate> poses;
  EstimatorSinks sinks;
  sinks.pose = [&](const PoseEstimate& e) { poses.push_back(e); };
  EstimatorNode node(test::testOptions(), ds.setup, sinks);
  for (const auto& in : mergeInTimeOrder(ds)) node.onInput(in);
  ASSERT_TRUE(node.initialized());
  ASSERT_GT(poses.size(), 3000u);
  // Compare at the ground-truth samples (same rate as the IMU).
  double max_p = 0.0, max_q = 0.0;
  size_t j = 0;
  for (const auto& e : poses) {
    while (j < ds.ground_truth.size() && ds.ground_truth[j].t < e.t) ++j;
    ASSERT_LT(j, ds.ground_truth.size());
    ASSERT_EQ(ds.ground_truth[j].t, e.t);
    max_p = std::max(max_p, (e.p_IinG - ds.ground_truth[j].p_IinG).norm());
    max_q = std::max(max_q, orientationErrorDeg(e.q_ItoG, ds.ground_truth[j].q_ItoG));
  }
  EXPECT_LT(max_p, 0.05);
  EXPECT_LT(max_q, 1.0);
  EXPECT_EQ(node.diagnostics().get("gated_range"), 0);
}

TEST(EstimatorNode, NoisyRunIsAccurateAndCovarianceStaysSymmetricPositiveDefinite) {
  synthetic::SyntheticOptions o;
  o.duration_s = 30.0;
  o.noise = true;
  o.n_estimated_anchors = 3;
  o.bias_acc_m_s2 = Eigen::Vector3d(0.05, -0.03, 0.04);
  o.bias_gyro_rad_s = Eigen::Vector3d(0.003, -0.002, 0.001);
  const Dataset ds = synthetic::makeSyntheticDataset(o);
  EstimatorNode node(test::testOptions(), ds.setup);
  const auto inputs = mergeInTimeOrder(ds);
  double sq = 0.0;
  int n = 0;
  for (size_t i = 0; i < inputs.size(); ++i) {
    node.onInput(inputs[i]);
    if (!node.initialized() || i % 25 != 0) continue;
    const Eigen::MatrixXd P = node.filter()->fullCovariance();
    ASSERT_EQ(P, P.transpose()) << "at input " << i;
    ASSERT_EQ(Eigen::LLT<Eigen::MatrixXd>(P).info(), Eigen::Success) << "at input " << i;
    const auto t = node.filter()->state().t;
    const auto& gt = ds.ground_truth[static_cast<size_t>(std::llround(t.sec() * o.imu_rate_hz))];
    if (gt.t == t) {
      sq += (node.filter()->state().imu.p_IinG - gt.p_IinG).squaredNorm();
      ++n;
    }
  }
  ASSERT_GT(n, 100);
  EXPECT_LT(std::sqrt(sq / n), 0.15);
  EXPECT_LT((node.filter()->state().imu.bias_gyro_rad_s - o.bias_gyro_rad_s).norm(), 0.001);
}

TEST(EstimatorNode, InitializesFromRangesWithoutInitialPose) {
  synthetic::SyntheticOptions o;
  o.duration_s = 6.0;
  o.with_initial_pose = false;
  o.noise = true;
  o.pair_rate_hz = 4.0;
  const Dataset ds = synthetic::makeSyntheticDataset(o);
  EstimatorNode node(test::testOptions(), ds.setup);
  for (const auto& in : mergeInTimeOrder(ds)) {
    node.onInput(in);
    if (node.initialized()) break;
  }
  ASSERT_TRUE(node.initialized());
  const auto t = node.filter()->state().t;
  EXPECT_LE(t.sec(), o.landed_s);
  const PoseSample& gt = ds.ground_truth[static_cast<size_t>(std::llround(t.sec() * o.imu_rate_hz))];
  EXPECT_LT((node.pose()->p_IinG - gt.p_IinG).norm(), 0.3);
  // Yaw is uncertain (large σ) but roll/pitch come from the accelerometer.
  EXPECT_GT(node.pose()->cov_theta_rad2.trace(), std::pow(20.0 * M_PI / 180.0, 2));
}

TEST(EstimatorNode, BadInputIsCountedAndDoesNotChangeTheEstimate) {
  synthetic::SyntheticOptions o;
  o.duration_s = 8.0;
  o.noise = true;
  const Dataset ds = synthetic::makeSyntheticDataset(o);
  const auto inputs = mergeInTimeOrder(ds);
  EstimatorNode clean(test::testOptions(), ds.setup), dirty(test::testOptions(), ds.setup);
  int n_bad = 0;
  for (size_t i = 0; i < inputs.size(); ++i) {
    clean.onInput(inputs[i]);
    dirty.onInput(inputs[i]);
    if (i % 97 != 0 || !dirty.initialized()) continue;
    const Timestamp t = inputTime(inputs[i]);
    RangeSample nan_range{t, 100, 101, UwbType::Tag, UwbType::Anchor, std::nan(""), 0.0, 0.0, true};
    dirty.onRange(nan_range);
    RangeSample unknown{t, 100, 999, UwbType::Tag, UwbType::Anchor, 3.0, 3.0, 0.01, true};
    dirty.onRange(unknown);
    RangeSample absurd{t, 100, 101, UwbType::Tag, UwbType::Anchor, -7.0, -7.0, 0.01, true};
    dirty.onRange(absurd);
    ImuSample nan_imu{t, Eigen::Vector3d(std::nan(""), 0, 9.8), Eigen::Vector3d::Zero()};
    dirty.onImu(nan_imu);
    dirty.onBaro({t, -5.0});
    ++n_bad;
  }
  ASSERT_GT(n_bad, 10);
  EXPECT_EQ(dirty.diagnostics().get("bad_input"), 4 * n_bad);
  EXPECT_EQ(dirty.diagnostics().get("unknown_id"), n_bad);
  EXPECT_EQ(test::stateDifference(*clean.filter(), *dirty.filter()), 0.0);
}

// A fleet's peer range (PeerRange, docs/fleet.md): exact ranges from tag 100 to a peer tag 500
// placed 3 m beside the true path, with the peer's position exact, are fused; malformed ones are
// counted and change nothing (a node fed both ends bit for bit where the node fed only the good
// ones does): bad values (the input gate: the same tag at both ends, a NaN position, a negative
// covariance) and a "peer" that is one of this vehicle's known anchors.
TEST(EstimatorNode, PeerRangesAreFusedAndMalformedOnesCountedWithoutEffect) {
  synthetic::SyntheticOptions o;
  o.duration_s = 8.0;
  o.noise = true;
  const Dataset ds = synthetic::makeSyntheticDataset(o);
  const auto inputs = mergeInTimeOrder(ds);
  const Eigen::Vector3d lever = ds.setup.rel_tag_positions.at(100);
  ASSERT_TRUE(ds.setup.abs_anchor_positions.count(101));
  EstimatorNode good(test::testOptions(), ds.setup), dirty(test::testOptions(), ds.setup);
  int n_peer = 0;
  for (size_t i = 0; i < inputs.size(); ++i) {
    good.onInput(inputs[i]);
    dirty.onInput(inputs[i]);
    if (i % 53 != 0 || !good.initialized()) continue;
    const Timestamp t = inputTime(inputs[i]) + Duration::fromSec(0.001);
    const auto truth = interpolatePose(ds.ground_truth, t);
    if (!truth) continue;
    const Eigen::Vector3d p_tag = truth->p_IinG + truth->q_ItoG * lever;
    PeerRange pr;
    pr.t = t;
    pr.peer_tag = 500;
    pr.p_peer_tag_in_G = p_tag + Eigen::Vector3d(3.0, 0.5, 0.2);
    pr.cov_peer_tag_m2 = Eigen::Matrix3d::Identity() * 1e-6;
    pr.range = RangeSample{t, 100, 500, UwbType::Tag, UwbType::Tag, 0.0, 0.0, 0.0, true};
    pr.range.range_m = pr.range.range_corr_m = (pr.p_peer_tag_in_G - p_tag).norm();
    good.onInput(pr);
    dirty.onInput(pr);
    auto later = [&](PeerRange x, int us) {  // another instant: not a duplicate of the good one
      x.t = x.range.t = t + Duration{us};
      return x;
    };
    PeerRange own = later(pr, 1);  // the same tag at both ends
    own.peer_tag = 100;
    own.range.id_responder = 100;
    dirty.onInput(own);
    PeerRange nan_pos = later(pr, 2);
    nan_pos.p_peer_tag_in_G.x() = std::nan("");
    dirty.onInput(nan_pos);
    PeerRange negative = later(pr, 3);
    negative.cov_peer_tag_m2 = -Eigen::Matrix3d::Identity();
    dirty.onInput(negative);
    PeerRange anchor = later(pr, 4);  // "peer" 101 is a known anchor of this vehicle
    anchor.peer_tag = 101;
    anchor.range.id_responder = 101;
    dirty.onInput(anchor);
    ++n_peer;
  }
  ASSERT_GT(n_peer, 10);
  EXPECT_EQ(good.diagnostics().get("peer_range_fused"), n_peer);
  EXPECT_EQ(dirty.diagnostics().get("bad_input"), 3 * n_peer);
  EXPECT_EQ(dirty.diagnostics().get("peer_range_invalid"), n_peer);
  EXPECT_EQ(test::stateDifference(*good.filter(), *dirty.filter()), 0.0);
}

TEST(EstimatorNode, OutputsAtTheirRates) {
  synthetic::SyntheticOptions o;
  o.duration_s = 10.0;
  const Dataset ds = synthetic::makeSyntheticDataset(o);
  EstimatorOptions opt = test::testOptions();
  opt.pose_output_rate_hz = 50.0;
  int poses = 0, anchor_msgs = 0, status_msgs = 0;
  EstimatorStatus last_status;
  EstimatorSinks sinks;
  sinks.pose = [&](const PoseEstimate&) { ++poses; };
  sinks.anchors = [&](const std::vector<AnchorEstimate>& a) {
    ++anchor_msgs;
    EXPECT_EQ(a.size(), 4u);
  };
  sinks.status = [&](const EstimatorStatus& s) {
    ++status_msgs;
    last_status = s;
  };
  EstimatorNode node(opt, ds.setup, sinks);
  for (const auto& in : mergeInTimeOrder(ds)) node.onInput(in);
  const double run_s = 10.0 - node.options().init.duration_s;
  EXPECT_NEAR(poses, 50.0 * run_s, 3.0);
  EXPECT_NEAR(anchor_msgs, run_s, 1.5);
  EXPECT_NEAR(status_msgs, 10.0, 1.5);  // also before initialization (heartbeat)
  EXPECT_TRUE(last_status.initialized);
  EXPECT_EQ(last_status.strategy, "centralized");
  EXPECT_GT(last_status.mean_step_us.count("propagate"), 0u);
  EXPECT_GT(last_status.mean_step_us.count("range_update"), 0u);
  EXPECT_GT(last_status.mean_step_us.count("zupt"), 0u);
  bool has_tag = false, has_imu = false;
  for (const auto& i : last_status.instances) {
    has_tag |= i.type == "tag" && i.n_updates > 0;
    has_imu |= i.type == "imu";
  }
  EXPECT_TRUE(has_tag);
  EXPECT_TRUE(has_imu);
}

TEST(EstimatorNode, AnchorInitAddsAnEstimatedAnchorThatIsRefined) {
  synthetic::SyntheticOptions o;
  o.duration_s = 20.0;
  o.noise = true;
  o.n_estimated_anchors = 1;  // anchor 106 is in the data …
  Dataset ds = synthetic::makeSyntheticDataset(o);
  const Eigen::Vector3d p_true = ds.setup.abs_anchor_positions.at(106);
  ds.setup.abs_anchor_positions.erase(106);  // … but unknown to the estimator
  ds.setup.abs_anchor_sigmas_m.erase(106);
  EstimatorNode node(test::testOptions(), ds.setup);
  const auto inputs = mergeInTimeOrder(ds);
  bool sent = false;
  for (const auto& in : inputs) {
    if (!sent && inputTime(in).sec() >= 6.0) {
      EXPECT_GT(node.diagnostics().get("unknown_id"), 0);
      AnchorInit init;
      init.t = inputTime(in);
      init.id = 106;
      init.p_AinG = p_true + Eigen::Vector3d(0.25, -0.2, 0.15);
      init.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.3 * 0.3;
      node.onAnchorInit(init);
      sent = true;
    }
    node.onInput(in);
  }
  const auto anchors = node.anchors();
  auto it = std::find_if(anchors.begin(), anchors.end(), [](const auto& a) { return a.id == 106; });
  ASSERT_NE(it, anchors.end());
  EXPECT_LT((it->p_AinG - p_true).norm(), 0.15);
  EXPECT_LT(it->cov_p_m2.trace(), 3 * 0.3 * 0.3);
  EXPECT_EQ(node.diagnostics().get("anchor_init"), 1);

  // Removing it at run time: its ranges become unknown again.
  const int64_t unknown_before = node.diagnostics().get("unknown_id");
  EstimatorCommand rm;
  rm.t = node.filter()->state().t;
  rm.action = EstimatorCommand::Action::RemoveInstance;
  rm.id = 106;
  node.onCommand(rm);
  EXPECT_EQ(node.filter()->state().values<AnchorKind>().count(106), 0u);
  RangeSample r{node.filter()->state().t + Duration::fromMs(1), 100, 106, UwbType::Tag, UwbType::Anchor, 4.0, 4.0, 0.01, true};
  node.onRange(r);
  node.flushHeld();  // stamped after the last IMU sample, it waits for the next one until then
  EXPECT_EQ(node.diagnostics().get("unknown_id"), unknown_before + 1);
}

TEST(EstimatorNode, UnknownStrategyIsRefusedAndModularOnesAreBuilt) {
  EstimatorOptions o;
  o.strategy = "fastest";
  EXPECT_THROW(EstimatorNode(o, synthetic::syntheticSetup({})), std::invalid_argument);
  for (const char* s : {"centralized", "dp", "dah"}) {
    o.strategy = s;
    EXPECT_NO_THROW(EstimatorNode(o, synthetic::syntheticSetup({}))) << s;
  }
}

TEST(EstimatorNode, HeightsAddABiasInstanceThatConvergesAndBadHeightsAreCounted) {
  synthetic::SyntheticOptions o;
  o.duration_s = 20.0;
  Dataset ds = synthetic::makeSyntheticDataset(o);
  // A rangefinder 0.1 m below the IMU, level flight: reads z − 0.1 (+ 0.08 floor offset as bias).
  const double bias = 0.08;
  ds.setup.height_p_IH = Eigen::Vector3d(0.0, 0.0, -0.1);
  for (size_t i = 0; i < ds.ground_truth.size(); i += 7) {
    const PoseSample& g = ds.ground_truth[i];
    const Eigen::Matrix3d R = g.q_ItoG.toRotationMatrix();
    const double s_z = (g.p_IinG + R * ds.setup.height_p_IH).z();
    ds.heights.push_back({g.t, s_z / R(2, 2) + bias});
  }
  EstimatorNode node(test::testOptions(), ds.setup);
  int n_bad = 0, n_low = 0;
  for (const auto& in : mergeInTimeOrder(ds)) {
    node.onInput(in);
    if (!node.initialized() || !std::holds_alternative<HeightSample>(in)) continue;
    const Timestamp t = inputTime(in);
    if (n_bad < 5) {
      node.onHeight({t, std::nan("")});
      node.onHeight({t, -1.0});
      n_bad += 2;
    } else if (n_low < 3) {
      node.onHeight({t, 0.1});  // below height.min_range_m: the sensor's clamped bottom reading
      ++n_low;
    }
  }
  ASSERT_TRUE(node.initialized());
  const NominalState& x = node.filter()->state();
  ASSERT_EQ(x.values<HeightBiasKind>().count(ds.setup.height_id), 1u);
  EXPECT_NEAR(x.values<HeightBiasKind>().at(ds.setup.height_id), bias, 0.03);
  EXPECT_EQ(node.diagnostics().get("bad_input"), n_bad);
  // Also the real readings while landed (z = 0.1 m: 0.08 m) after initialization.
  int n_low_data = 0;
  for (const auto& h : ds.heights) n_low_data += h.range_m < node.options().height.min_range_m;
  EXPECT_GT(n_low_data, 0);
  EXPECT_GE(node.diagnostics().get("height_below_min_range"), n_low);
  EXPECT_LE(node.diagnostics().get("height_below_min_range"), n_low + n_low_data);
  EXPECT_EQ(node.diagnostics().get("gated_height"), 0);
  bool listed = false;
  for (const auto& is : node.status().instances) listed |= is.id == ds.setup.height_id && is.type == "height";
  EXPECT_TRUE(listed);
}

TEST(EstimatorNode, AnAnchorWithASensorInstanceIdOrBadValuesIsRefusedAlsoByCommand) {
  // Found by an audit: ANCHOR_INIT 2 replaced the baro bias state (every later BARO sample threw),
  // ANCHOR_INIT 1 left the IMU half replaced, and ESTIMATOR_CMD's anchor skipped every value check
  // once the filter ran. (An anchor on height_id is one while no height came: next test.) Each is now refused and counted, and the estimate stays as without it.
  synthetic::SyntheticOptions o;
  o.duration_s = 8.0;
  o.noise = true;
  const Dataset ds = synthetic::makeSyntheticDataset(o);
  const auto inputs = mergeInTimeOrder(ds);
  EstimatorNode clean(test::testOptions(), ds.setup), dirty(test::testOptions(), ds.setup);
  bool injected = false;
  for (const auto& in : inputs) {
    clean.onInput(in);
    dirty.onInput(in);
    if (injected || !dirty.initialized() || inputTime(in).sec() < 5.0) continue;
    injected = true;
    AnchorInit a;
    a.t = inputTime(in);
    a.p_AinG = {1.0, 2.0, 3.0};
    a.cov_p_m2 = 0.01 * Eigen::Matrix3d::Identity();
    for (SensorId id : {ds.setup.imu_id, ds.setup.baro_id}) {
      a.id = id;
      dirty.onAnchorInit(a);  // bad_command: a sensor instance's id
    }
    a.id = ds.setup.rel_tag_positions.begin()->first;
    dirty.onAnchorInit(a);  // bad_command: a tag's id
    EstimatorCommand c;
    c.t = a.t;
    c.action = EstimatorCommand::Action::AddAnchor;
    c.id = 130;
    c.anchor = a;
    c.anchor.cov_p_m2 = -0.01 * Eigen::Matrix3d::Identity();  // not positive definite
    dirty.onCommand(c);
    c.anchor = a;
    c.anchor.biases.push_back(PairBias{100, 130, 0.0, -1.0, 0.1, 0.0, 0.0});  // β ≤ 0
    dirty.onCommand(c);
    c.anchor = a;
    c.id = 0;
    c.anchor.id = -4;  // no id anywhere
    dirty.onCommand(c);
  }
  ASSERT_TRUE(injected);
  EXPECT_EQ(dirty.diagnostics().get("bad_command"), 3);
  EXPECT_EQ(dirty.diagnostics().get("bad_input"), 3);
  EXPECT_EQ(dirty.diagnostics().get("BARO:handler_error"), 0);
  EXPECT_EQ(dirty.filter()->layout().find(130), nullptr);
  EXPECT_EQ(test::stateDifference(*clean.filter(), *dirty.filter()), 0.0);
}

TEST(EstimatorNode, AnAnchorOnTheHeightIdIsOneUntilHeightsComeAndThenTheyAreRefused) {
  // height_id is an instance only once heights come: without a height sensor an unknown anchor
  // numbered like the default height_id (3) is calibrated and fused as any other. Whichever comes
  // first keeps the id; the other is refused and counted, never swapped.
  synthetic::SyntheticOptions o;
  o.duration_s = 8.0;
  const Dataset ds = synthetic::makeSyntheticDataset(o);
  const auto inputs = mergeInTimeOrder(ds);
  AnchorInit a;
  a.id = ds.setup.height_id;
  a.p_AinG = {1.0, 2.0, 3.0};
  a.cov_p_m2 = 0.01 * Eigen::Matrix3d::Identity();
  {
    EstimatorNode node(test::testOptions(), ds.setup);
    bool added = false;
    for (const auto& in : inputs) {
      node.onInput(in);
      if (added || !node.initialized() || inputTime(in).sec() < 5.0) continue;
      added = true;
      a.t = inputTime(in);
      node.onAnchorInit(a);
      node.onHeight({inputTime(in), 1.0});
    }
    ASSERT_TRUE(added);
    EXPECT_NE(node.filter()->layout().find(ds.setup.height_id), nullptr);
    EXPECT_EQ(node.filter()->state().values<AnchorKind>().count(ds.setup.height_id), 1u);
    EXPECT_EQ(node.diagnostics().get("height_id_is_an_anchor"), 1);
    EXPECT_EQ(node.diagnostics().get("bad_command"), 0);
  }
  EstimatorNode node(test::testOptions(), ds.setup);
  bool height = false, added = false;
  for (const auto& in : inputs) {
    node.onInput(in);
    if (!node.initialized() || inputTime(in).sec() < 5.0) continue;
    if (!height) {
      height = true;
      node.onHeight({inputTime(in), 1.0});
    } else if (!added && inputTime(in).sec() >= 6.0) {
      added = true;
      a.t = inputTime(in);
      node.onAnchorInit(a);
    }
  }
  ASSERT_TRUE(added);
  EXPECT_EQ(node.filter()->state().values<HeightBiasKind>().count(ds.setup.height_id), 1u);
  EXPECT_EQ(node.filter()->state().values<AnchorKind>().count(ds.setup.height_id), 0u);
  EXPECT_EQ(node.diagnostics().get("bad_command"), 1);
}

TEST(EstimatorNode, ACorrectedRangeFarFromTheRawOneIsBadInputWhenUsed) {
  // real-t1-a3-loiter and old serial-bridge logs carry range_corr = 0: with
  // uwb.use_corrected_range those were fused as 0 m ranges.
  synthetic::SyntheticOptions o;
  o.duration_s = 30.0;
  const Dataset ds = synthetic::makeSyntheticDataset(o);
  EstimatorOptions opt = test::testOptions();
  RangeSample r{Timestamp::fromSec(1.0), 100, 101, UwbType::Tag, UwbType::Anchor, 4.0, 0.0, 0.0, true};
  {
    EstimatorNode raw(opt, ds.setup);  // the corrected range is not used: nothing to refuse
    raw.onRange(r);
    EXPECT_EQ(raw.diagnostics().get("bad_input"), 0);
  }
  opt.uwb.use_corrected_range = true;
  EstimatorNode node(opt, ds.setup);
  node.onRange(r);
  EXPECT_EQ(node.diagnostics().get("bad_input"), 1);
  r.t = Timestamp::fromSec(1.1);
  r.range_corr_m = 3.85;  // a correction of 0.15 m
  node.onRange(r);
  EXPECT_EQ(node.diagnostics().get("bad_input"), 1);
}

TEST(EstimatorNode, AMeasurementAfterTheLastImuSampleWaitsForTheNextOneButNotThroughAGap) {
  const Dataset ds = synthetic::makeSyntheticDataset(test::shortNoisyFlight(1));
  const auto inputs = mergeInTimeOrder(ds);
  EstimatorOptions opt = test::testOptions();
  opt.imu.hold_for_next_sample = true;
  EstimatorNode node(opt, ds.setup);
  // Up to the first range after 6 s that falls between two IMU samples.
  size_t i = 0;
  for (; i < inputs.size(); ++i) {
    const auto* r = std::get_if<RangeSample>(&inputs[i]);
    if (r && r->t.sec() > 6.0 && node.initialized() && r->t > node.filter()->state().t) break;
    node.onInput(inputs[i]);
  }
  ASSERT_LT(i, inputs.size());
  ASSERT_TRUE(node.initialized());
  // Measurements fused or gated so far, over every instance.
  auto fates = [&node] {
    int64_t n = 0;
    for (const auto& s : node.status().instances) n += s.n_updates + s.n_rejected;
    return n;
  };
  const Timestamp last_imu_t = node.filter()->state().t;
  const Timestamp range_t = inputTime(inputs[i]);
  const int64_t fates_before = fates();
  node.onInput(inputs[i]);
  // Held: the filter stays at the last sample until the next one has come, the range undecided.
  EXPECT_EQ(node.filter()->state().t, last_imu_t);
  size_t j = i + 1;
  for (; !std::holds_alternative<ImuSample>(inputs[j]); ++j) node.onInput(inputs[j]);
  EXPECT_EQ(fates(), fates_before);
  node.onInput(inputs[j]);  // the next sample releases it, then propagates to itself
  EXPECT_EQ(node.filter()->state().t, inputTime(inputs[j]));
  EXPECT_GT(fates(), fates_before);
  EXPECT_GT(inputTime(inputs[j]), range_t);

  // The end of a stream: flushHeld processes what waits.
  size_t k = j + 1;
  for (; !std::holds_alternative<RangeSample>(inputs[k]); ++k) node.onInput(inputs[k]);
  ASSERT_GT(inputTime(inputs[k]), node.filter()->state().t);
  const int64_t fates_before_flush = fates();
  node.onInput(inputs[k]);
  EXPECT_LT(node.filter()->state().t, inputTime(inputs[k]));
  node.flushHeld();
  EXPECT_EQ(node.filter()->state().t, inputTime(inputs[k]));
  EXPECT_GT(fates(), fates_before_flush);
  j = k;

  // The IMU stops: the ranges after it wait at most imu.max_dt_s, then go on the gap's readings.
  const Timestamp imu_end = node.filter()->state().t;
  Timestamp last_range_t = imu_end;
  const int64_t fates_before_gap = fates();
  int tag_ranges = 0;
  for (size_t k = j + 1; k < inputs.size() && inputTime(inputs[k]) < imu_end + Duration::fromSec(0.3); ++k)
    if (const auto* r = std::get_if<RangeSample>(&inputs[k])) {
      node.onInput(*r);
      last_range_t = r->t;
      tag_ranges += ds.setup.isTag(r->id_initiator) != ds.setup.isTag(r->id_responder);
    }
  ASSERT_GT((last_range_t - imu_end).sec(), 0.25);
  ASSERT_GE(tag_ranges, 5);
  // No sample is due in a gap: the ranges past imu.max_dt_s are processed at once, and those
  // held before it was clear have been released: every tag range has its fate.
  EXPECT_EQ(node.filter()->state().t, last_range_t);
  EXPECT_GE(fates() - fates_before_gap, tag_ranges);
}
