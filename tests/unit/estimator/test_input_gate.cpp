/// InputGate (estimator/node/input_gate.h): values no sensor gives refused as "bad_input" with a
/// message naming channel and time, the time guard (refusal ahead/behind, commands restamped, a
/// backwards jump of the whole stream as kClockBack) and duplicates within the window.
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <limits>
#include <sstream>

#include "estimator/node/input_gate.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }

/// Everything spdlog logs while it lives (the gate's messages go through Diagnostics::report).
class LogCapture {
 public:
  LogCapture() : previous_(spdlog::default_logger()) {
    auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(out_);
    sink->set_pattern("%v");
    spdlog::set_default_logger(std::make_shared<spdlog::logger>("capture", sink));
  }
  ~LogCapture() { spdlog::set_default_logger(previous_); }
  std::string text() const { return out_.str(); }

 private:
  std::ostringstream out_;
  std::shared_ptr<spdlog::logger> previous_;
};

ImuSample imu(double t, const Eigen::Vector3d& acc = {0, 0, 9.81}) { return {at(t), acc, Eigen::Vector3d::Zero()}; }

RangeSample range(double t, double z, SensorId a = 100, SensorId b = 101, double corr = -1.0) {
  RangeSample r;
  r.t = at(t);
  r.id_initiator = a;
  r.id_responder = b;
  r.range_m = z;
  r.range_corr_m = corr < 0.0 ? z : corr;
  return r;
}

AnchorInit anchorInit(double t, SensorId id) {
  AnchorInit a;
  a.t = at(t);
  a.id = id;
  a.p_AinG = {1.0, 2.0, 3.0};
  return a;
}

EstimatorOptions gateOptions() {
  EstimatorOptions o;
  o.window_s = 1.0;
  o.uwb.max_range_m = 100.0;
  o.time.max_offset_s = 5.0;
  o.time.rebase_after = 3;
  return o;
}

struct InputGateTest : ::testing::Test {
  EstimatorOptions options = gateOptions();
  Diagnostics diag;
  InputGate gate{options, diag};
  void SetUp() override { diag.max_logged_per_kind = 1000; }
  /// valid(in), and the bad_input count went up by one exactly when it is false.
  bool valid(const EstimatorInput& in) {
    const int64_t before = diag.get("bad_input");
    const bool ok = gate.valid(in);
    EXPECT_EQ(diag.get("bad_input") - before, ok ? 0 : 1) << inputKindName(in);
    return ok;
  }
};

}  // namespace

TEST_F(InputGateTest, BadValuesAreRefusedWithChannelAndTime) {
  LogCapture log;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(valid(imu(3.0)));
  EXPECT_FALSE(valid(imu(3.0, {nan, 0, 9.81})));
  EXPECT_NE(log.text().find("IMU t=3.000000"), std::string::npos) << log.text();
  EXPECT_FALSE(valid(imu(3.1, {600.0, 0, 0})));  // beyond any accelerometer
  EXPECT_FALSE(valid(ImuSample{at(3.2), {0, 0, 9.81}, {0, std::numeric_limits<double>::infinity(), 0}}));

  EXPECT_TRUE(valid(BaroSample{at(4.0), 101325.0}));
  EXPECT_FALSE(valid(BaroSample{at(4.5), 500.0}));
  EXPECT_NE(log.text().find("BARO t=4.500000"), std::string::npos) << log.text();
  EXPECT_FALSE(valid(BaroSample{at(4.6), 250000.0}));
  EXPECT_FALSE(valid(BaroSample{at(4.7), nan}));

  EXPECT_TRUE(valid(HeightSample{at(5.0), 1.2}));
  EXPECT_FALSE(valid(HeightSample{at(5.1), -0.1}));
  EXPECT_NE(log.text().find("HEIGHT t=5.100000"), std::string::npos) << log.text();

  EXPECT_TRUE(valid(anchorInit(6.0, 106)));
  AnchorInit bad = anchorInit(6.5, 106);
  bad.p_AinG.x() = nan;
  EXPECT_FALSE(valid(bad));
  EXPECT_NE(log.text().find("ANCHOR_INIT t=6.500000"), std::string::npos) << log.text();
  EXPECT_EQ(diag.get("bad_input"), 8);
}

TEST_F(InputGateTest, RangesOutsideTheirBoundsOrBetweenInvalidIdsAreRefused) {
  LogCapture log;
  EXPECT_TRUE(valid(range(12.0, 99.9)));
  EXPECT_TRUE(valid(range(12.0, -0.5)));  // bounds included
  EXPECT_TRUE(valid(range(12.0, 100.0)));
  EXPECT_FALSE(valid(range(12.3, 100.1)));
  EXPECT_NE(log.text().find("RANGE t=12.300000: bad range"), std::string::npos) << log.text();
  EXPECT_FALSE(valid(range(12.4, -0.51)));
  EXPECT_FALSE(valid(range(12.5, std::nan(""))));
  RangeSample neg_R = range(12.6, 5.0);
  neg_R.R_m2 = -0.01;
  EXPECT_FALSE(valid(neg_R));

  EXPECT_FALSE(valid(range(13.0, 5.0, 101, 101)));  // equal ids
  EXPECT_NE(log.text().find("RANGE t=13.000000: invalid ids 101, 101"), std::string::npos) << log.text();
  EXPECT_FALSE(valid(range(13.1, 5.0, 0, 101)));
  EXPECT_FALSE(valid(range(13.2, 5.0, 100, -3)));
  EXPECT_TRUE(valid(range(13.3, 5.0, 101, 100)));  // either device may initiate
}

TEST_F(InputGateTest, ACorrectedRangeFarFromTheRawOneIsNoCorrection) {
  ASSERT_DOUBLE_EQ(InputGate::kMaxRangeCorrection_m, 1.0);
  // Without uwb.use_corrected_range the corrected value is not looked at (old logs carry 0).
  EXPECT_TRUE(valid(range(1.0, 5.0, 100, 101, 0.0)));
  options.uwb.use_corrected_range = true;  // the gate reads the node's options
  LogCapture log;
  EXPECT_TRUE(valid(range(2.0, 5.0, 100, 101, 5.9)));
  EXPECT_TRUE(valid(range(2.0, 5.0, 100, 101, 4.0)));  // exactly 1 m: still a correction
  EXPECT_FALSE(valid(range(2.5, 5.0, 100, 101, 6.2)));
  EXPECT_NE(log.text().find("RANGE t=2.500000: corrected range"), std::string::npos) << log.text();
  EXPECT_FALSE(valid(range(3.0, 5.0, 100, 101, 0.0)));  // a source that leaves it at 0
  // The bounds apply to the corrected value.
  EXPECT_FALSE(valid(range(3.5, 99.5, 100, 101, 100.3)));
}

TEST_F(InputGateTest, MeasurementsFarFromTheClockAreRefusedPerKind) {
  EstimatorInput first = imu(100.0);
  EXPECT_EQ(gate.admitTime(first), InputGate::Verdict::kAdmitted);  // sets the clock
  EstimatorInput ok = imu(104.9);
  EXPECT_EQ(gate.admitTime(ok), InputGate::Verdict::kAdmitted);
  EstimatorInput ahead = imu(110.0);  // 5.1 s ahead of 104.9
  EXPECT_EQ(gate.admitTime(ahead), InputGate::Verdict::kRefused);
  EXPECT_EQ(diag.get("IMU:time_ahead"), 1);
  EstimatorInput behind = range(99.0, 5.0);  // 5.9 s behind
  EXPECT_EQ(gate.admitTime(behind), InputGate::Verdict::kRefused);
  EXPECT_EQ(diag.get("RANGE:time_behind"), 1);
  EXPECT_EQ(inputTime(behind), at(99.0));  // a refused measurement is not restamped
  // The refused ones did not move the clock: 104.9 + 5 is still within.
  EstimatorInput within = imu(109.8);
  EXPECT_EQ(gate.admitTime(within), InputGate::Verdict::kAdmitted);
}

TEST_F(InputGateTest, CommandsFarFromTheClockAreRestampedToIt) {
  // Before any measurement there is no clock: a command keeps its time and does not set one.
  EstimatorInput early = anchorInit(500.0, 106);
  EXPECT_EQ(gate.admitTime(early), InputGate::Verdict::kAdmitted);
  EXPECT_EQ(inputTime(early), at(500.0));
  EstimatorInput first = imu(20.0);
  EXPECT_EQ(gate.admitTime(first), InputGate::Verdict::kAdmitted);
  EXPECT_EQ(diag.get("IMU:time_behind"), 0);

  EstimatorInput far = anchorInit(500.0, 106);
  EXPECT_EQ(gate.admitTime(far), InputGate::Verdict::kAdmitted);
  EXPECT_EQ(inputTime(far), at(20.0));
  EXPECT_EQ(diag.get("ANCHOR_INIT:time_clamped"), 1);
  EstimatorInput near = anchorInit(24.0, 107);  // within the offset: unchanged
  EXPECT_EQ(gate.admitTime(near), InputGate::Verdict::kAdmitted);
  EXPECT_EQ(inputTime(near), at(24.0));
  EstimatorCommand c;
  c.t = at(1.0);
  c.action = EstimatorCommand::Action::Reset;
  EstimatorInput cmd = c;
  EXPECT_EQ(gate.admitTime(cmd), InputGate::Verdict::kAdmitted);
  EXPECT_EQ(inputTime(cmd), at(20.0));
  EXPECT_EQ(diag.get("ESTIMATOR_CMD:time_clamped"), 1);
  EXPECT_EQ(diag.get("ANCHOR_INIT:time_clamped"), 1);
}

TEST_F(InputGateTest, AStreamThatJumpsBackIsClockBackAfterRebaseAfterInputs) {
  for (double t : {100.0, 100.01, 100.02}) {
    EstimatorInput in = imu(t);
    ASSERT_EQ(gate.admitTime(in), InputGate::Verdict::kAdmitted);
  }
  // Three agreeing inputs 60 s back (time.rebase_after = 3): the first two refused, the third
  // moves the clock and tells the node to start over.
  EstimatorInput b1 = imu(40.0), b2 = range(40.005, 5.0), b3 = imu(40.01);
  EXPECT_EQ(gate.admitTime(b1), InputGate::Verdict::kRefused);
  EXPECT_EQ(gate.admitTime(b2), InputGate::Verdict::kRefused);
  EXPECT_EQ(gate.admitTime(b3), InputGate::Verdict::kClockBack);
  EXPECT_EQ(diag.get("time_rebased"), 1);
  EstimatorInput next = imu(40.02);
  EXPECT_EQ(gate.admitTime(next), InputGate::Verdict::kAdmitted);
  // A jump forwards moves the clock too, but is no clock-back.
  EstimatorInput f1 = imu(300.0), f2 = imu(300.01), f3 = imu(300.02);
  EXPECT_EQ(gate.admitTime(f1), InputGate::Verdict::kRefused);
  EXPECT_EQ(gate.admitTime(f2), InputGate::Verdict::kRefused);
  EXPECT_EQ(gate.admitTime(f3), InputGate::Verdict::kAdmitted);
  EXPECT_EQ(diag.get("time_rebased"), 2);
}

TEST_F(InputGateTest, TheSameInputTwiceIsADuplicate) {
  const std::optional<Timestamp> newest = at(10.0);
  EXPECT_TRUE(gate.admitOnce(range(10.0, 5.0), newest));
  EXPECT_FALSE(gate.admitOnce(range(10.0, 5.3), newest));  // same time and ids: the value does not matter
  EXPECT_EQ(diag.get("RANGE:duplicate"), 1);
  EXPECT_TRUE(gate.admitOnce(range(10.0, 5.0, 100, 102), newest));  // other ids
  EXPECT_TRUE(gate.admitOnce(imu(10.0), newest));                   // other kind
  EXPECT_FALSE(gate.admitOnce(imu(10.0), newest));
  EXPECT_EQ(diag.get("IMU:duplicate"), 1);
  EXPECT_TRUE(gate.admitOnce(range(10.000001, 5.0), newest));  // 1 µs later
  EXPECT_TRUE(gate.admitOnce(anchorInit(10.0, 106), newest));
  EXPECT_FALSE(gate.admitOnce(anchorInit(10.0, 106), newest));
  EXPECT_EQ(diag.get("ANCHOR_INIT:duplicate"), 1);
}

TEST_F(InputGateTest, KeysOlderThanTheWindowAreForgotten) {
  EXPECT_TRUE(gate.admitOnce(range(10.0, 5.0), at(10.0)));
  // No newest time: nothing is forgotten.
  EXPECT_FALSE(gate.admitOnce(range(10.0, 5.0), std::nullopt));
  // newest − window_s = 10.0: the key at 10.0 is still within the window.
  EXPECT_FALSE(gate.admitOnce(range(10.0, 5.0), at(11.0)));
  EXPECT_EQ(diag.get("RANGE:duplicate"), 2);
  // 1 µs later it is older than the window and forgotten: the same key is admitted again.
  EXPECT_TRUE(gate.admitOnce(range(10.0, 5.0), at(11.000001)));
  EXPECT_EQ(diag.get("RANGE:duplicate"), 2);
}

TEST_F(InputGateTest, ForgetKeysAdmitsEverythingAgain) {
  const std::optional<Timestamp> newest = at(5.0);
  EXPECT_TRUE(gate.admitOnce(imu(5.0), newest));
  EXPECT_TRUE(gate.admitOnce(range(5.0, 3.0), newest));
  gate.forgetKeys();
  EXPECT_TRUE(gate.admitOnce(imu(5.0), newest));
  EXPECT_TRUE(gate.admitOnce(range(5.0, 3.0), newest));
  EXPECT_FALSE(gate.admitOnce(range(5.0, 3.0), newest));
  EXPECT_EQ(diag.get("RANGE:duplicate"), 1);
  EXPECT_EQ(diag.get("IMU:duplicate"), 0);
}
