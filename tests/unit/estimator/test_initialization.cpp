/// Initialization (estimator/init/initialization.h): stillness as the evidence of rest (landedAt)
/// until a flight state decides, what the node waits for, the heights fed to the in-motion
/// alignment (usable ones only, thinned to height.align_rate_hz), the height-source rules
/// (baroAligns, carriedHeightUsed, heightLever) and a first belief from a short landed scenario.
#include <gtest/gtest.h>

#include <cmath>

#include "estimator/init/initialization.h"
#include "estimator/testing/synthetic_scenario.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }

ImuSample restingImu(double t) { return {at(t), {0.0, 0.0, 9.81}, Eigen::Vector3d::Zero()}; }
ImuSample turningImu(double t) { return {at(t), {0.0, 0.0, 9.81}, {0.0, 0.0, 0.5}}; }

/// An Initialization with its own options, setup and counters.
struct Init {
  EstimatorOptions options;
  SystemSetup setup;
  Diagnostics diag;
  StepTimings timings;
  UwbNetwork network;
  std::unique_ptr<Initialization> init;
  explicit Init(EstimatorOptions o = {}, SystemSetup s = {}) : options(std::move(o)), setup(std::move(s)) {
    network = UwbNetwork(setup, options.uwb.sigma_range_m);
    init = std::make_unique<Initialization>(options, setup, diag, timings);
  }
  void feed(const EstimatorInput& in) { init->feed(in, network, nullptr); }
};

/// The synthetic flight (landed for 3 s, then moving) with a level-corrected rangefinder reading
/// at every IMU sample (200 Hz), no rangefinder lever.
Dataset flightWithHeights(double duration_s) {
  synthetic::SyntheticOptions o;
  o.duration_s = duration_s;
  Dataset ds = synthetic::makeSyntheticDataset(o);
  for (const PoseSample& g : ds.ground_truth)
    ds.heights.push_back({g.t, g.p_IinG.z() / g.q_ItoG.toRotationMatrix()(2, 2)});
  return ds;
}

}  // namespace

TEST(Initialization, StillnessDecidesRestUntilAFlightStateComes) {
  Init s;
  for (int k = 0; k <= 200; ++k) s.feed(restingImu(0.005 * k));  // 1 s at rest
  EXPECT_FALSE(s.init->landedAt(at(0.1), true));  // the detector's window is not full yet
  EXPECT_TRUE(s.init->landedAt(at(0.9), false));  // stillness, not `current`
  EXPECT_FALSE(s.init->landedAt(at(0.9025), true));  // no verdict at a time never fed
  for (int k = 1; k <= 100; ++k) s.feed(turningImu(1.0 + 0.005 * k));
  EXPECT_FALSE(s.init->landedAt(at(1.5), true));  // turning at 0.5 rad/s is no rest
  // Verdicts are kept per IMU time (rewinds ask about the past) until pruned.
  EXPECT_TRUE(s.init->landedAt(at(0.9), false));
  s.init->pruneStillness(at(0.95).us);
  EXPECT_FALSE(s.init->landedAt(at(0.9), false));
  EXPECT_TRUE(s.init->landedAt(at(0.95), false));
  // A flight state: from now on `current` decides, whatever stillness said.
  EXPECT_FALSE(s.init->haveFlightState());
  s.feed(FlightStateSample{at(1.6), false});
  EXPECT_TRUE(s.init->haveFlightState());
  EXPECT_FALSE(s.init->landedAt(at(0.95), false));
  EXPECT_TRUE(s.init->landedAt(at(1.5), true));
  // A re-run's replay node takes both the flight state and the verdicts.
  Init replay;
  replay.init->copyStillnessFrom(*s.init);
  EXPECT_TRUE(replay.init->haveFlightState());
  // forgetStreams (clock back): stillness decides again, from nothing.
  s.init->forgetStreams();
  EXPECT_FALSE(s.init->haveFlightState());
  EXPECT_FALSE(s.init->landedAt(at(0.95), true));
}

TEST(Initialization, WithoutStillnessDetectionNorFlightStateNothingSaysLanded) {
  // Resting IMU data, but stillness detection off and no flight state: no evidence of rest, whatever
  // the node's current flag (which starts landed and nothing else would ever clear: a whole flight
  // of ZUPTs, found on a hover of the widened sweep).
  EstimatorOptions o;
  o.zupt.detect_stillness = false;
  Init s(o);
  for (int k = 0; k <= 200; ++k) s.feed(restingImu(0.005 * k));
  EXPECT_FALSE(s.init->landedAt(at(0.9), false));
  EXPECT_FALSE(s.init->landedAt(at(0.9), true));
  // Unless the user says such a vehicle rests.
  o.init.assume_landed_without_flight_state = true;
  Init assumed(o);
  for (int k = 0; k <= 200; ++k) assumed.feed(restingImu(0.005 * k));
  EXPECT_TRUE(assumed.init->landedAt(at(0.9), false));
  // With detection on, the detector decides (rest here), not the flag.
  Init detecting;
  for (int k = 0; k <= 200; ++k) detecting.feed(restingImu(0.005 * k));
  EXPECT_TRUE(detecting.init->landedAt(at(0.9), false));
}

TEST(Initialization, WaitingForSaysWhatIsMissingBeforeData) {
  Init s;
  EXPECT_FALSE(s.init->waitingFor().empty());
  EXPECT_NE(s.init->waitingFor().find("landed IMU data"), std::string::npos) << s.init->waitingFor();
  // Only an IMU sample can initialize.
  EXPECT_FALSE(s.init->tryInitialize(BaroSample{at(0.0), 101325.0}, true));
}

TEST(Initialization, OnlyUsableHeightsOrBaroReadingsCountAsVerticalSensors) {
  Init s;
  EXPECT_FALSE(s.init->sawVerticalSensor());
  s.feed(HeightSample{at(1.0), 0.29});  // below height.min_range_m: not fed
  EXPECT_FALSE(s.init->sawVerticalSensor());
  s.feed(HeightSample{at(1.1), 1.2});
  EXPECT_TRUE(s.init->sawVerticalSensor());
  // reset() empties the alignment window: its heights are gone.
  s.init->reset();
  EXPECT_FALSE(s.init->sawVerticalSensor());
  // A pressure reading is kept across reset(), not across forgetStreams().
  s.feed(BaroSample{at(2.0), 101000.0});
  s.init->reset();
  EXPECT_TRUE(s.init->sawVerticalSensor());
  s.init->forgetStreams();
  EXPECT_FALSE(s.init->sawVerticalSensor());

  for (const bool off_by_rate : {true, false}) {
    EstimatorOptions o;
    if (off_by_rate)
      o.height.align_rate_hz = 0.0;  // heights not fed to the alignment
    else
      o.height.enabled = false;
    Init t(o);
    for (int k = 0; k < 50; ++k) t.feed(HeightSample{at(0.1 * k), 1.2});
    EXPECT_FALSE(t.init->sawVerticalSensor()) << off_by_rate;
  }
}

TEST(Initialization, HeightsAreThinnedToTheAlignRate) {
  // 200 heights a second in a 12 s window; the aligner gets height.align_rate_hz of them (rates
  // that stay below the aligner's own cap of 200 heights per window).
  const Dataset ds = flightWithHeights(18.0);
  int n_heights[2] = {0, 0};
  for (const double rate : {2.0, 8.0}) {
    EstimatorOptions o;
    o.height.align_rate_hz = rate;
    Init s(o, ds.setup);
    for (const EstimatorInput& in : mergeInTimeOrder(ds)) s.feed(in);
    ASSERT_TRUE(s.init->sawVerticalSensor());
    const auto r = s.init->align(Eigen::Vector3d::Zero());
    ASSERT_TRUE(r) << s.init->alignerReason();
    EXPECT_GT(r->n_heights, 0);
    // One per period of the window (both ends included), every one an inlier (exact data).
    EXPECT_LE(r->n_heights, static_cast<int>(std::floor(r->window_s * rate)) + 1) << rate;
    EXPECT_GE(r->n_heights, static_cast<int>(std::floor(r->window_s * rate)) - 1) << rate;
    n_heights[rate > 5.0] = r->n_heights;
  }
  EXPECT_NEAR(static_cast<double>(n_heights[1]) / n_heights[0], 4.0, 0.2);
}

TEST(Initialization, HeightSourceRules) {
  EstimatorOptions o;
  SystemSetup s;
  s.height_p_IH = {0.0, 0.1, -0.2};
  // No reference pressure: the baro does not align; the rangefinder's lever.
  EXPECT_FALSE(baroAligns(o, s));
  EXPECT_FALSE(carriedHeightUsed(o, s));
  EXPECT_EQ(heightLever(o, s), Eigen::Vector3d(0.0, 0.1, -0.2));
  s.baro_reference_pressure_pa = 97000.0;
  EXPECT_TRUE(baroAligns(o, s));
  EstimatorOptions no_use = o;
  no_use.init.motion_use_baro = false;
  EXPECT_FALSE(baroAligns(no_use, s));
  EstimatorOptions baro_off = o;
  baro_off.baro.enabled = false;
  EXPECT_FALSE(baroAligns(baro_off, s));
  // A carried height: used (unless turned off), no lever, and the baro no longer aligns.
  s.carried_height = CarriedHeight{1.2, 0.3};
  EXPECT_TRUE(carriedHeightUsed(o, s));
  EXPECT_FALSE(baroAligns(o, s));
  EXPECT_TRUE(heightLever(o, s).isZero(0.0));
  EstimatorOptions carried_off = o;
  carried_off.carried_height.enabled = false;
  EXPECT_FALSE(carriedHeightUsed(carried_off, s));
  EXPECT_TRUE(baroAligns(carried_off, s));
  EXPECT_EQ(heightLever(carried_off, s), Eigen::Vector3d(0.0, 0.1, -0.2));
  // The object says the same.
  Init with_carried(o, s);
  EXPECT_TRUE(with_carried.init->carriedHeight());
  EXPECT_FALSE(with_carried.init->baroAligns());
  Init with_baro(carried_off, s);
  EXPECT_FALSE(with_baro.init->carriedHeight());
  EXPECT_TRUE(with_baro.init->baroAligns());
}

TEST(Initialization, AShortLandedScenarioGivesABelief) {
  for (const bool flight_state : {true, false}) {
    synthetic::SyntheticOptions so;
    so.duration_s = 3.0;  // landed all along
    so.landed_s = 3.5;
    Dataset ds = synthetic::makeSyntheticDataset(so);
    if (!flight_state) ds.flight_states.clear();  // stillness tells the rest
    Init s({}, ds.setup);
    std::optional<InitialBelief> b;
    for (const EstimatorInput& in : mergeInTimeOrder(ds)) {
      s.feed(in);
      if ((b = s.init->tryInitialize(in, flight_state))) break;
    }
    ASSERT_TRUE(b) << s.init->waitingFor();
    EXPECT_GE(b->t.sec(), 1.0) << "init.duration_s of landed data first";
    EXPECT_LT(b->t.sec(), 2.5);
    EXPECT_TRUE(b->landed);
    EXPECT_LT((b->imu.p_IinG - ds.setup.initial_pose->p_IinG).norm(), 0.05);
    EXPECT_LT(b->imu.v_IinG.norm(), 1e-6);
    const Eigen::Matrix3d R = b->imu.q_ItoG.toRotationMatrix();
    EXPECT_NEAR(std::atan2(R(1, 0), R(0, 0)), so.yaw0_deg * M_PI / 180.0, 0.05);  // initial pose's yaw
    EXPECT_NEAR(R(2, 2), 1.0, 1e-4);                                             // level
    EXPECT_EQ(b->last_imu.t, b->t);
  }
}
