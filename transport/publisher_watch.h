#pragma once
/// @file publisher_watch.h
/// @brief Who publishes each channel, from the `sender_id` every message carries (the random
/// instance id of the publishing process, lcmtypes/README.md): a second process publishing POSE,
/// ESTIMATOR_STATUS, … under the same channel name (a second launch by mistake, a log played back
/// with its outputs) is detected, logged and counted instead of being merged into one stream.
///
/// Instance ids (newInstanceId) hold the process's start time in their high bits, so the smaller
/// of two ids is the instance that started first (LcmNode lets the later one yield).
///
/// An id counts from its second message on (kConfirmMessages): a corrupted message that still
/// decodes carries a random id once and must neither replace a publisher nor stop a process; its
/// message passes as any message did before sender ids.
///
/// Model. A channel of one publisher (channels::hasOnePublisher) has an *owner*, the sender of
/// its messages. A new sender replaces the owner: that is a restart (a respawn after a crash, an
/// operator's restart), after which the old instance never speaks again. A sender that speaks
/// again after it was replaced, while the one that replaced it is alive (heard within
/// kLiveness_s), is the proof of two live publishers: no restart brings an old instance id back.
/// From then on the channel keeps the one this receiver heard first (the stream its state was
/// built on) and drops the other's messages while both are alive, counted
/// "<CHANNEL>:second_publisher"; the first conflict with each sender is logged as an error. A
/// restart is counted "<CHANNEL>:publisher_changed". Sender 0 (unknown: an older log's message)
/// is always accepted and not tracked. Channels of several publishers (RANGE from one bridge per
/// anchor, commands, time-sync requests) are not watched.
///
/// A channel this process publishes itself: any other sender on it is a second publisher (the
/// process's own messages, looped back, are its own id). LcmNode (transport/lcm_node.h) uses
/// this to refuse to run beside another instance of itself.
///
/// LCM-free (plain ids, channel names, wall times), unit-tested in
/// tests/unit/transport/test_publisher_watch.cpp.

#include <cstdint>
#include <map>
#include <set>
#include <string>

#include "common/diagnostics.h"

namespace meshnav::transport {

class PublisherWatch {
 public:
  /// `own_id`: this process's instance id; `diag` receives the counters and messages.
  PublisherWatch(int64_t own_id, Diagnostics& diag) : own_id_(own_id), diag_(diag) {}

  /// Records that this process publishes `channel`: every other sender on it is a second publisher.
  void markPublished(const std::string& channel) { published_.insert(channel); }
  bool published(const std::string& channel) const { return published_.count(channel) > 0; }

  /// One message of `sender` on `channel` (a channel of one publisher), received at wall time
  /// `wall_us`. Returns false when it comes from a second publisher and is to be dropped
  /// (counted, the first time logged).
  bool observe(const std::string& channel, int64_t sender, int64_t wall_us);

  /// Whether a message of `sender` on `channel` is used, as decided by the messages observed so
  /// far (the typed subscriptions ask this after the watch observed the same message): not when
  /// `sender` is a second publisher.
  bool accepts(const std::string& channel, int64_t sender) const;

  /// Channels on which a second publisher was seen, with its instance ids.
  std::map<std::string, std::set<int64_t>> secondPublishers() const;

  /// An instance id as printed in messages: 0x and 16 hex digits.
  static std::string format(int64_t id);
  /// A new instance id: the wall time `wall_us` in ms in bits 20–62 (until the year 2248), 20
  /// random bits below; never 0. The smaller of two ids started first (same ms: either).
  static int64_t newInstanceId(int64_t wall_us);
  /// Whether instance `a` started before instance `b` (ids of newInstanceId).
  static bool startedBefore(int64_t a, int64_t b) { return static_cast<uint64_t>(a) < static_cast<uint64_t>(b); }

  /// Messages of one id before it counts as a publisher.
  static constexpr int kConfirmMessages = 2;
  /// An owner silent this long [s] is gone: another sender may take the channel without a
  /// conflict. Three of the processes' default 1 s heartbeats (a sporadic channel such as
  /// ANCHOR_INIT is seldom "alive": its publisher's heartbeat channel shows the conflict).
  static constexpr double kLiveness_s = 3.0;

 private:
  static constexpr size_t kMaxCandidates = 64;
  struct SenderState {
    int64_t order = 0;         ///< 1 for the first publisher heard on the channel, 2 ...
    int64_t last_wall_us = 0;  ///< when its last message was received
  };
  struct ChannelState {
    int64_t owner = 0;
    int64_t next_order = 0;
    std::set<int64_t> confirmed;             ///< ids seen kConfirmMessages times: publishers
    std::map<int64_t, SenderState> senders;  ///< the publishers heard
    std::set<int64_t> rivals;                ///< senders whose messages are dropped
    std::map<int64_t, int> candidates;       ///< ids seen fewer than kConfirmMessages times
  };
  /// Whether `sender` is (now) a confirmed publisher of the channel.
  bool confirmed(ChannelState& st, int64_t sender);
  bool observeOwn(const std::string& channel, int64_t sender);

  int64_t own_id_;
  Diagnostics& diag_;
  std::set<std::string> published_;
  std::map<std::string, ChannelState> channels_;
};

}  // namespace meshnav::transport
