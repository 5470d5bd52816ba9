// PublisherWatch (transport/publisher_watch.h): which sender a channel of one publisher keeps —
// a restart replaces the owner, an old sender that speaks again proves two live publishers (the
// earlier keeps the channel), unknown senders pass, and on a channel of this process every
// other sender is a second publisher.
#include <gtest/gtest.h>

#include "transport/publisher_watch.h"

using meshnav::Diagnostics;
using meshnav::transport::PublisherWatch;

namespace {
constexpr int64_t kSelf = 0x5e1f;
constexpr int64_t kA = 0xa, kB = 0xb, kC = 0xc;
constexpr int kN = PublisherWatch::kConfirmMessages;

int64_t g_wall_us = 1'000'000;  ///< the receiver's wall clock: 10 ms per message

/// `n` messages of `sender`; true when the last one was accepted.
bool speak(PublisherWatch& w, const std::string& ch, int64_t sender, int n = kN) {
  bool last = true;
  for (int i = 0; i < n; ++i) last = w.observe(ch, sender, g_wall_us += 10'000);
  return last;
}
bool observe(PublisherWatch& w, const std::string& ch, int64_t sender) { return speak(w, ch, sender, 1); }
/// Nothing is received for `s` seconds.
void silence(double s) { g_wall_us += static_cast<int64_t>(s * 1e6); }
}  // namespace

TEST(PublisherWatch, OneSenderIsAlwaysAccepted) {
  Diagnostics diag;
  PublisherWatch w(kSelf, diag);
  EXPECT_TRUE(observe(w, "POSE", kA));  // the first message of an id: not yet a publisher
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(observe(w, "POSE", kA));
  EXPECT_TRUE(w.accepts("POSE", kA));
  EXPECT_EQ(diag.total(), 0);
  EXPECT_TRUE(w.secondPublishers().empty());
}

TEST(PublisherWatch, ARestartReplacesTheOwner) {
  Diagnostics diag;
  PublisherWatch w(kSelf, diag);
  EXPECT_TRUE(speak(w, "POSE", kA));
  EXPECT_TRUE(speak(w, "POSE", kB));  // A never speaks again: a restart
  EXPECT_TRUE(speak(w, "POSE", kB));
  EXPECT_TRUE(speak(w, "POSE", kC));  // and another one
  EXPECT_EQ(diag.get("POSE:publisher_changed"), 2);
  EXPECT_EQ(diag.get("POSE:second_publisher"), 0);
  EXPECT_TRUE(w.secondPublishers().empty());
}

TEST(PublisherWatch, AnOldSenderSpeakingAgainProvesTwoPublishersAndTheEarlierKeepsTheChannel) {
  Diagnostics diag;
  PublisherWatch w(kSelf, diag);
  EXPECT_TRUE(speak(w, "POSE", kA));
  EXPECT_TRUE(speak(w, "POSE", kB));    // taken for a restart at first
  EXPECT_TRUE(observe(w, "POSE", kA));   // A is alive: two publishers; A came first and keeps it
  EXPECT_FALSE(observe(w, "POSE", kB));  // B's messages are dropped from now on
  EXPECT_FALSE(observe(w, "POSE", kB));
  EXPECT_TRUE(observe(w, "POSE", kA));
  EXPECT_FALSE(w.accepts("POSE", kB));
  EXPECT_TRUE(w.accepts("POSE", kA));
  EXPECT_EQ(diag.get("POSE:second_publisher"), 3);  // the conflict, then B's two messages
  const auto second = w.secondPublishers();
  ASSERT_EQ(second.size(), 1u);
  EXPECT_EQ(second.at("POSE"), std::set<int64_t>{kB});
  // Another channel is not affected.
  EXPECT_TRUE(speak(w, "ANCHORS", kB));
}

TEST(PublisherWatch, TheOneHeardFirstKeepsTheChannelWhateverTheIds) {
  Diagnostics diag;
  PublisherWatch w(kSelf, diag);
  EXPECT_TRUE(speak(w, "POSE", kB));  // B first (a live estimator), then A (a log with older ids)
  EXPECT_TRUE(speak(w, "POSE", kA));
  EXPECT_TRUE(observe(w, "POSE", kB));
  EXPECT_FALSE(observe(w, "POSE", kA));
}

TEST(PublisherWatch, ASenderWhoseOwnerFellSilentTakesTheChannel) {
  Diagnostics diag;
  PublisherWatch w(kSelf, diag);
  // Two logs played one after the other, then the first again: each replaces a silent one.
  EXPECT_TRUE(speak(w, "IMU", kA, 50));
  silence(PublisherWatch::kLiveness_s + 0.5);
  EXPECT_TRUE(speak(w, "IMU", kB, 50));
  silence(PublisherWatch::kLiveness_s + 0.5);
  EXPECT_TRUE(speak(w, "IMU", kA, 50));
  EXPECT_EQ(diag.get("IMU:second_publisher"), 0);
  EXPECT_EQ(diag.get("IMU:publisher_changed"), 2);
  // Two live ones (B speaks again while A does): B is dropped while A speaks ...
  EXPECT_FALSE(speak(w, "IMU", kB));
  EXPECT_TRUE(observe(w, "IMU", kA));
  EXPECT_FALSE(observe(w, "IMU", kB));
  EXPECT_EQ(w.secondPublishers().at("IMU"), std::set<int64_t>{kB});
  // ... and takes the channel once A has stopped.
  silence(PublisherWatch::kLiveness_s + 0.5);
  EXPECT_TRUE(observe(w, "IMU", kB));
  EXPECT_TRUE(w.secondPublishers().empty());
}

TEST(PublisherWatch, ACorruptedMessagesRandomIdIsNoPublisher) {
  Diagnostics diag;
  PublisherWatch w(kSelf, diag);
  w.markPublished("ESTIMATOR_STATUS");
  EXPECT_TRUE(speak(w, "POSE", kA));
  // A thousand messages, each with an id of its own (random bytes that still decode): they pass
  // as before, and neither replace A nor count as a second publisher, here or on an own channel.
  for (int64_t i = 0; i < 1000; ++i) {
    EXPECT_TRUE(observe(w, "POSE", 0x100000 + 7919 * i));
    EXPECT_TRUE(observe(w, "ESTIMATOR_STATUS", 0x200000 + 7919 * i));
  }
  EXPECT_TRUE(speak(w, "POSE", kA, 1));
  EXPECT_EQ(diag.total(), 0);
  EXPECT_TRUE(w.secondPublishers().empty());
}

TEST(PublisherWatch, UnknownSendersPassAndAreNotTracked) {
  Diagnostics diag;
  PublisherWatch w(kSelf, diag);
  EXPECT_TRUE(speak(w, "IMU", kA));
  EXPECT_TRUE(speak(w, "IMU", 0));  // an older log's message
  EXPECT_TRUE(speak(w, "IMU", kA));
  EXPECT_TRUE(w.accepts("IMU", 0));
  EXPECT_EQ(diag.total(), 0);
}

TEST(PublisherWatch, OnItsOwnChannelEveryOtherSenderIsASecondPublisher) {
  Diagnostics diag;
  PublisherWatch w(kSelf, diag);
  w.markPublished("ESTIMATOR_STATUS");
  EXPECT_TRUE(observe(w, "ESTIMATOR_STATUS", kSelf));  // its own, looped back
  EXPECT_TRUE(w.secondPublishers().empty());
  EXPECT_FALSE(speak(w, "ESTIMATOR_STATUS", kA));
  EXPECT_FALSE(observe(w, "ESTIMATOR_STATUS", kA));
  EXPECT_EQ(w.secondPublishers().at("ESTIMATOR_STATUS"), std::set<int64_t>{kA});
  EXPECT_EQ(diag.get("ESTIMATOR_STATUS:second_publisher"), 2);
  EXPECT_FALSE(w.accepts("ESTIMATOR_STATUS", kA));
  EXPECT_TRUE(w.accepts("ESTIMATOR_STATUS", kSelf));
}

TEST(PublisherWatch, InstanceIdsOrderByStartTime) {
  const int64_t t = 1'796'000'000'000'000;  // µs since the epoch, 2026
  for (int i = 0; i < 100; ++i) {
    const int64_t earlier = PublisherWatch::newInstanceId(t);
    const int64_t later = PublisherWatch::newInstanceId(t + 1000);  // 1 ms later
    EXPECT_GT(earlier, 0);
    EXPECT_TRUE(PublisherWatch::startedBefore(earlier, later));
    EXPECT_FALSE(PublisherWatch::startedBefore(later, earlier));
  }
  EXPECT_NE(PublisherWatch::newInstanceId(0), 0);
}

TEST(PublisherWatch, FormatsIdsAsSixteenHexDigits) {
  EXPECT_EQ(PublisherWatch::format(0xab), "0x00000000000000ab");
  EXPECT_EQ(PublisherWatch::format(-1), "0xffffffffffffffff");
}
