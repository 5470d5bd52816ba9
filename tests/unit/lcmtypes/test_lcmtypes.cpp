// The generated LCM types encode and decode losslessly, refuse foreign bytes, and carry the
// constants the processes rely on.
#include <gtest/gtest.h>

#include <vector>

#include "meshnav/anchor_estimate_t.hpp"
#include "meshnav/anchor_init_t.hpp"
#include "meshnav/anchors_t.hpp"
#include "meshnav/baro_t.hpp"
#include "meshnav/height_t.hpp"
#include "meshnav/calib_anchor_status_t.hpp"
#include "meshnav/calib_cmd_t.hpp"
#include "meshnav/calib_status_t.hpp"
#include "meshnav/counter_t.hpp"
#include "meshnav/estimator_cmd_t.hpp"
#include "meshnav/estimator_status_t.hpp"
#include "meshnav/flight_state_t.hpp"
#include "meshnav/ground_truth_t.hpp"
#include "meshnav/imu_t.hpp"
#include "meshnav/instance_status_t.hpp"
#include "meshnav/mission_status_t.hpp"
#include "meshnav/pair_bias_t.hpp"
#include "meshnav/pose_t.hpp"
#include "meshnav/range_t.hpp"
#include "meshnav/control_cmd_t.hpp"
#include "meshnav/control_status_t.hpp"
#include "meshnav/time_sync_t.hpp"
#include "meshnav/timing_t.hpp"

namespace {

template <class Msg>
std::vector<uint8_t> encode(const Msg& m) {
  std::vector<uint8_t> buf(static_cast<size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  return buf;
}

template <class Msg>
Msg decode(const std::vector<uint8_t>& buf) {
  Msg m;
  EXPECT_EQ(m.decode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  return m;
}

}  // namespace

TEST(LcmTypes, ImuRoundTrip) {
  meshnav::imu_t m;
  m.utime = 1234567;
  m.sender_id = 0x1a2b3c;
  for (int i = 0; i < 3; ++i) {
    m.lin_acc[i] = 0.1 * i - 9.81;
    m.ang_vel[i] = -0.01 * i;
  }
  const auto d = decode<meshnav::imu_t>(encode(m));
  EXPECT_EQ(d.utime, m.utime);
  EXPECT_EQ(d.sender_id, m.sender_id);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(d.lin_acc[i], m.lin_acc[i]);
    EXPECT_EQ(d.ang_vel[i], m.ang_vel[i]);
  }
}

TEST(LcmTypes, RangeConstantsAreAsciiCodes) {
  EXPECT_EQ(meshnav::range_t::TYPE_TAG, 'T');
  EXPECT_EQ(meshnav::range_t::TYPE_ANCHOR, 'A');
  meshnav::range_t m{};
  m.utime = -5;
  m.id_initiator = 100;
  m.id_responder = 101;
  m.type_initiator = meshnav::range_t::TYPE_TAG;
  m.type_responder = meshnav::range_t::TYPE_ANCHOR;
  m.range = 4.25;
  m.range_corr = 4.0;
  m.variance = 0.01;
  m.los = true;
  const auto d = decode<meshnav::range_t>(encode(m));
  EXPECT_EQ(d.utime, -5);
  EXPECT_EQ(d.id_responder, 101);
  EXPECT_EQ(d.type_initiator, 'T');
  EXPECT_DOUBLE_EQ(d.range, 4.25);
  EXPECT_TRUE(d.los);
}

TEST(LcmTypes, NestedArraysRoundTrip) {
  meshnav::estimator_status_t m{};
  m.utime = 42;
  m.wall_utime = 1700000000000000;
  m.initialized = true;
  m.strategy = "dah";
  m.instances.resize(2);
  m.instances[0].id = 1;
  m.instances[0].type = "imu";
  m.instances[1].id = 101;
  m.instances[1].type = "anchor";
  m.instances[1].num_updates = 77;
  m.num_instances = 2;
  m.counters.resize(1);
  m.counters[0].name = "gated_range";
  m.counters[0].value = 3;
  m.num_counters = 1;
  m.num_timings = 0;
  const auto d = decode<meshnav::estimator_status_t>(encode(m));
  ASSERT_EQ(d.instances.size(), 2u);
  EXPECT_EQ(d.instances[1].type, "anchor");
  EXPECT_EQ(d.instances[1].num_updates, 77);
  ASSERT_EQ(d.counters.size(), 1u);
  EXPECT_EQ(d.counters[0].name, "gated_range");
  EXPECT_EQ(d.strategy, "dah");
}

TEST(LcmTypes, AnchorInitInsideEstimatorCommand) {
  meshnav::estimator_cmd_t m{};
  m.utime = 80000000;
  m.action = meshnav::estimator_cmd_t::ADD_ANCHOR;
  m.id = 106;
  m.anchor.id = 106;
  m.anchor.p_AinG[2] = 3.256;
  m.anchor.cov_p[0] = m.anchor.cov_p[4] = m.anchor.cov_p[8] = 0.04;
  m.anchor.biases.resize(1);
  m.anchor.biases[0].a = 100;
  m.anchor.biases[0].b = 106;
  m.anchor.biases[0].gamma = 0.21;
  m.anchor.biases[0].beta = 1.01;
  m.anchor.num_biases = 1;
  m.anchor.num_inliers = 300;
  const auto d = decode<meshnav::estimator_cmd_t>(encode(m));
  EXPECT_EQ(d.anchor.p_AinG[2], 3.256);
  ASSERT_EQ(d.anchor.biases.size(), 1u);
  EXPECT_EQ(d.anchor.biases[0].gamma, 0.21);
  EXPECT_EQ(d.anchor.num_inliers, 300);
}

TEST(LcmTypes, ForeignBytesAreRefused) {
  meshnav::baro_t b{};
  b.utime = 1;
  b.pressure = 101325.0;
  const auto buf = encode(b);
  meshnav::imu_t imu;  // a baro message is not an IMU message: the fingerprint differs
  EXPECT_LT(imu.decode(buf.data(), 0, static_cast<int>(buf.size())), 0);
  meshnav::baro_t truncated;
  EXPECT_LT(truncated.decode(buf.data(), 0, static_cast<int>(buf.size()) - 1), 0);
}

TEST(LcmTypes, FingerprintsAreDistinct) {
  const std::vector<int64_t> hashes = {
      meshnav::imu_t::getHash(),          meshnav::baro_t::getHash(),          meshnav::height_t::getHash(),
      meshnav::range_t::getHash(),        meshnav::flight_state_t::getHash(),
      meshnav::ground_truth_t::getHash(), meshnav::pose_t::getHash(),
      meshnav::anchors_t::getHash(),      meshnav::anchor_init_t::getHash(),
      meshnav::estimator_status_t::getHash(), meshnav::estimator_cmd_t::getHash(),
      meshnav::calib_cmd_t::getHash(),    meshnav::calib_status_t::getHash(),
      meshnav::mission_status_t::getHash(), meshnav::anchor_estimate_t::getHash(),
      meshnav::calib_anchor_status_t::getHash(), meshnav::counter_t::getHash(),
      meshnav::instance_status_t::getHash(), meshnav::pair_bias_t::getHash(),
      meshnav::timing_t::getHash(),          meshnav::time_sync_t::getHash(),
      meshnav::control_cmd_t::getHash(),     meshnav::control_status_t::getHash()};
  ASSERT_EQ(hashes.size(), 23u);  // every type in lcmtypes/types
  for (size_t i = 0; i < hashes.size(); ++i)
    for (size_t j = i + 1; j < hashes.size(); ++j) EXPECT_NE(hashes[i], hashes[j]) << i << " vs " << j;
}
