// Older messages read as current ones (transport/wire_versions.h): a message of the version
// before issue 36 (no sender_id), as an older build's logs, journals and processes send it, is
// decoded field for field with sender_id 0; a damaged one is refused; over LcmNode it reaches the
// typed handler and is counted "<CHANNEL>:older_version".
#include <gtest/gtest.h>

#include <vector>

#include "transport/channels.h"
#include "transport/lcm_node.h"
#include "transport/wire_versions.h"

using namespace meshnav;
using namespace meshnav::transport;

namespace {

template <class Msg>
std::vector<uint8_t> encode(const Msg& m) {
  std::vector<uint8_t> buf(static_cast<size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  return buf;
}

/// The same field values on either version (the fields are named alike).
auto fillPose = [](auto& m) {
  m.utime = 1234567;
  for (int i = 0; i < 3; ++i) {
    m.p_IinG[i] = 1.5 + i;
    m.v_IinG[i] = -0.25 * i;
    m.bias_gyro[i] = 1e-3 * i;
    m.bias_acc[i] = -2e-2 * i;
  }
  m.q_ItoG[0] = 0.5;
  m.q_ItoG[1] = 0.5;
  m.q_ItoG[2] = -0.5;
  m.q_ItoG[3] = 0.5;
  for (int i = 0; i < 9; ++i) m.cov_p[i] = m.cov_v[i] = m.cov_theta[i] = i % 4 == 0 ? 0.01 * (i + 1) : 0.0;
};

auto fillCommand = [](auto& m) {
  m.utime = 42;
  m.action = 0;
  m.id = 107;
  auto& a = m.anchor;
  a.utime = 41;
  a.id = 107;
  for (int i = 0; i < 3; ++i) a.p_AinG[i] = 3.0 * i;
  for (int i = 0; i < 9; ++i) a.cov_p[i] = i % 4 == 0 ? 0.04 : 0.0;
  a.num_biases = 2;
  a.biases.resize(2);
  for (int k = 0; k < 2; ++k) {
    a.biases[k].a = 107;
    a.biases[k].b = 101 + k;
    a.biases[k].gamma = 0.1 * (k + 1);
    a.biases[k].beta = 0.01;
    a.biases[k].sigma = 0.1;
    a.biases[k].sigma_gamma = 0.02;
    a.biases[k].sigma_beta = 0.001;
  }
  a.num_inliers = 300;
  a.num_outliers = 7;
  a.num_gamma_cov = 2;
  a.cov_gamma_p.assign(2, std::vector<double>(3, 0.001));
  a.cov_gamma.assign(2, std::vector<double>(2, 0.0004));
};

}  // namespace

TEST(WireVersions, ThePreviousFingerprintsAreThoseOlderBuildsWrote) {
  // dd8ab84's generated headers (the last build before sender_id): what its logs carry.
  EXPECT_EQ(static_cast<uint64_t>(meshnav_pre36::pose_t::getHash()), 0x2bbd293d2dcd61cbULL);
  EXPECT_EQ(static_cast<uint64_t>(meshnav_pre36::estimator_cmd_t::getHash()), 0x03b8c64865d8be74ULL);
  EXPECT_EQ(static_cast<uint64_t>(meshnav_pre36::imu_t::getHash()), 0xc5101482d2d70bebULL);
  EXPECT_NE(meshnav_pre36::pose_t::getHash(), meshnav::pose_t::getHash());
}

TEST(WireVersions, AnOlderPoseDecodesFieldForFieldWithAnUnknownSender) {
  meshnav_pre36::pose_t old;
  fillPose(old);
  const std::vector<uint8_t> bytes = encode(old);
  meshnav::pose_t now;
  bool older = false;
  ASSERT_EQ(decodeAnyVersion(bytes.data(), bytes.size(), now, &older), static_cast<int>(bytes.size()));
  EXPECT_TRUE(older);
  EXPECT_EQ(now.sender_id, 0);
  meshnav::pose_t expected;
  fillPose(expected);
  expected.sender_id = 0;
  EXPECT_EQ(encode(now), encode(expected));
}

TEST(WireVersions, AnOlderCommandWithItsNestedAnchorDecodesFieldForField) {
  meshnav_pre36::estimator_cmd_t old;
  fillCommand(old);
  const std::vector<uint8_t> bytes = encode(old);
  meshnav::estimator_cmd_t now;
  bool older = false;
  ASSERT_EQ(decodeAnyVersion(bytes.data(), bytes.size(), now, &older), static_cast<int>(bytes.size()));
  EXPECT_TRUE(older);
  EXPECT_EQ(now.sender_id, 0);
  EXPECT_EQ(now.anchor.sender_id, 0);
  meshnav::estimator_cmd_t expected;
  fillCommand(expected);
  expected.sender_id = 0;
  expected.anchor.sender_id = 0;
  EXPECT_EQ(encode(now), encode(expected));
}

TEST(WireVersions, ACurrentMessageIsReadAsItIs) {
  meshnav::pose_t m;
  fillPose(m);
  m.sender_id = 0x1234;
  const std::vector<uint8_t> bytes = encode(m);
  meshnav::pose_t now;
  bool older = true;
  ASSERT_EQ(decodeAnyVersion(bytes.data(), bytes.size(), now, &older), static_cast<int>(bytes.size()));
  EXPECT_FALSE(older);
  EXPECT_EQ(now.sender_id, 0x1234);
}

TEST(WireVersions, ADamagedOlderMessageIsRefusedNotPaddedIntoAValidOne) {
  meshnav_pre36::estimator_cmd_t old;
  fillCommand(old);
  std::vector<uint8_t> bytes = encode(old);
  // Cut by as many bytes as the current version adds: padding them back would make a message of
  // the right length, so only decoding the older version first refuses it.
  for (int cut : {1, 8, 16}) {
    const std::vector<uint8_t> shorter(bytes.begin(), bytes.end() - cut);
    meshnav::estimator_cmd_t now;
    EXPECT_LT(decodeAnyVersion(shorter.data(), shorter.size(), now), 0) << cut;
  }
}

TEST(WireVersions, OverLcmAnOlderMessageReachesTheHandlerAndIsCounted) {
  LcmNode node("test", "memq://");
  std::vector<PoseEstimate> got;
  node.subscribe(channels::kPose, [&](const PoseEstimate& e) { got.push_back(e); });
  meshnav_pre36::pose_t old;
  fillPose(old);
  const std::vector<uint8_t> bytes = encode(old);
  ASSERT_EQ(node.lcm().publish(channels::kPose.name, bytes.data(), static_cast<unsigned>(bytes.size())), 0);
  while (node.spinOnce(0) > 0) {
  }
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].t.us, 1234567);
  EXPECT_DOUBLE_EQ(got[0].p_IinG.y(), 2.5);
  EXPECT_EQ(node.diagnostics().get("POSE:older_version"), 1);
  EXPECT_EQ(node.diagnostics().get("POSE:decode_error"), 0);
}
