// SensorFaults (sim/sensor_faults.h): the drills' IMU gaps, an anchor switched off and RANGE loss
// take exactly those samples away (seeded), the truth stays, and bad options are refused.
#include <gtest/gtest.h>

#include <stdexcept>

#include "sim/sensor_faults.h"

using namespace meshnav;
using namespace meshnav::sim;

namespace {

VehicleOutputs outputsAt(double t_s, int n_ranges, SensorId anchor) {
  VehicleOutputs o;
  o.imu.push_back(ImuSample{});
  o.imu.back().t = Timestamp::fromSec(t_s);
  o.truth.push_back(PoseSample{});
  o.truth.back().t = Timestamp::fromSec(t_s);
  for (int i = 0; i < n_ranges; ++i) {
    SimulatedRange r;
    r.sample.t = Timestamp::fromSec(t_s);
    r.sample.id_initiator = 1;
    r.sample.id_responder = static_cast<SensorId>(anchor + (i % 2));
    o.ranges.push_back(r);
  }
  return o;
}

}  // namespace

TEST(SensorFaults, NoFaultPassesEverything) {
  SensorFaults f({}, 1);
  VehicleOutputs o = outputsAt(1.0, 10, 101);
  f.apply(o);
  EXPECT_EQ(o.imu.size(), 1u);
  EXPECT_EQ(o.ranges.size(), 10u);
  EXPECT_EQ(f.options().toString(), "none");
}

TEST(SensorFaults, ImuGapDropsImuInTheWindowOnlyAndKeepsTheTruth) {
  SensorFaultOptions opt;
  opt.imu_gaps_s = {{50.0, 53.0}};
  SensorFaults f(opt, 1);
  int kept = 0;
  for (double t : {49.995, 50.0, 51.5, 52.995, 53.0}) {
    VehicleOutputs o = outputsAt(t, 0, 101);
    f.apply(o);
    kept += static_cast<int>(o.imu.size());
    EXPECT_EQ(o.truth.size(), 1u);
  }
  EXPECT_EQ(kept, 2);
  EXPECT_EQ(f.imuDropped(), 3);
}

TEST(SensorFaults, AnchorOffDropsItsRangesFromItsTime) {
  SensorFaultOptions opt;
  opt.anchor_off = 101;
  opt.anchor_off_from_s = 30.0;
  SensorFaults f(opt, 1);
  VehicleOutputs before = outputsAt(29.0, 10, 101);  // responders 101, 102 alternating
  f.apply(before);
  EXPECT_EQ(before.ranges.size(), 10u);
  VehicleOutputs after = outputsAt(31.0, 10, 101);
  f.apply(after);
  ASSERT_EQ(after.ranges.size(), 5u);
  for (const auto& r : after.ranges) EXPECT_EQ(r.sample.id_responder, 102u);
  EXPECT_EQ(f.rangesAnchorOff(), 5);
}

TEST(SensorFaults, RangeLossIsAboutItsFractionAndSeeded) {
  SensorFaultOptions opt;
  opt.range_loss_fraction = 0.2;
  SensorFaults a(opt, 7), b(opt, 7);
  size_t kept_a = 0, kept_b = 0;
  for (int k = 0; k < 100; ++k) {
    VehicleOutputs oa = outputsAt(k * 0.1, 100, 101), ob = outputsAt(k * 0.1, 100, 101);
    a.apply(oa);
    b.apply(ob);
    kept_a += oa.ranges.size();
    kept_b += ob.ranges.size();
  }
  EXPECT_EQ(kept_a, kept_b);  // the same seed loses the same ranges
  EXPECT_EQ(a.rangesLost(), static_cast<int64_t>(10000 - kept_a));
  EXPECT_NEAR(static_cast<double>(a.rangesLost()) / 10000.0, 0.2, 0.02);  // 5 sigma of the binomial
}

TEST(SensorFaults, BadOptionsAreRefused) {
  SensorFaultOptions opt;
  opt.imu_gaps_s = {{5.0, 5.0}};
  EXPECT_THROW(SensorFaults(opt, 1), std::invalid_argument);
  opt.imu_gaps_s.clear();
  opt.range_loss_fraction = 1.0;
  EXPECT_THROW(SensorFaults(opt, 1), std::invalid_argument);
  opt.range_loss_fraction = -0.1;
  EXPECT_THROW(SensorFaults(opt, 1), std::invalid_argument);
}
