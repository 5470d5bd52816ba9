#pragma once
/// @file lcm_node.h
/// @brief The small runtime every process uses: one LCM instance, typed subscriptions (on the
/// typed channels of transport/channels.h) that decode
/// and validate messages themselves (a malformed message is reported with its channel, counted,
/// and dropped: never a crash), a loop with a periodic heartbeat, and a clean stop on SIGINT /
/// SIGTERM (StopSignal) or on request.
///
/// Counter keys in diagnostics(): "<CHANNEL>:decode_error" (bytes that do not decode as the
/// channel's type; the report names a foreign fingerprint, and a retired version of the type —
/// an older log — by name), "<CHANNEL>:invalid_message" (decoded, but NaN / unknown code),
/// "<CHANNEL>:handler_error" (the callback threw), "lcm:publish_error", "<CHANNEL>:oversized"
/// (a received message above kMaxMessageBytes, dropped before decoding) and
/// "<CHANNEL>:oversized_publish" (a message of ours above it, not sent), "<CHANNEL>:older_version"
/// (a message of the type's previous version, read with an unknown sender: transport/wire_versions.h),
/// "<CHANNEL>:second_publisher" and "<CHANNEL>:publisher_changed" (below).
///
/// Publishers: every LcmNode draws a random instance id at construction and stamps it into the
/// `sender_id` of every message it publishes. Each channel of one publisher
/// (channels::hasOnePublisher) that the node subscribes, or publishes from inside spin(), is watched by a
/// PublisherWatch (transport/publisher_watch.h): the messages of a second publisher are dropped
/// before a typed handler sees them, logged and counted. On a channel the node publishes itself,
/// another sender within kSecondInstanceWindow_s (5 s) of its first publication there means that this process is
/// the second instance (a second launch of the same processes, or a log played back with its
/// outputs) when the other started first (instance ids hold the start time): the node stops,
/// and ProcessMain ends the process with kExitSecondInstance (7), leaving the channel to the
/// other; the older one only counts it, and after the window neither is stopped (a process that
/// has run for a while is never stopped by another one appearing).
///
/// Vehicle prefix: a node made with a channel prefix P (a process's `--channel-prefix`, a vehicle
/// of a fleet) publishes and subscribes every typed channel under channels::prefixed(channel, P)
/// (`P/POSE`; the fleet's shared channels unchanged), and waitForMessage prefixes the name it is
/// given the same way. Raw subscriptions (regexes) are left as given.
///
/// Size: meshnav's messages are small (the largest, ANCHORS or a status with many counters, is a
/// few KiB). Over udpm, LCM itself drops a message larger than its receive ring buffer (about
/// 1000 KiB in LCM 1.3) before any subscriber sees it, with a line on stderr only; such a message
/// cannot be counted by the receiver. So every LcmNode refuses to publish a message above
/// kMaxMessageBytes (counted at the sender), and counts and drops one it receives (a message that
/// LCM still delivers, e.g. from a foreign publisher over memq or a larger buffer).

#include <lcm/lcm-cpp.hpp>

#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "common/diagnostics.h"
#include "common/time.h"
#include "transport/channels.h"
#include "transport/convert.h"
#include "transport/replay/clock.h"
#include "transport/publisher_watch.h"
#include "transport/wire_versions.h"

namespace meshnav::transport {

/// Fingerprints of message versions this code no longer reads, with what they were: a log
/// recorded before a message changed is refused by name, never misread (lcmtypes/README.md).
struct RetiredFingerprint {
  int64_t hash;
  const char* what;
};
const std::vector<RetiredFingerprint>& retiredFingerprints();
/// Empty when the first 8 bytes of `rbuf` are `expected` (or there are fewer than 8); else why the
/// message is not a `type_name`: "an older version of <type> (...)" for a retired fingerprint,
/// else "fingerprint 0x… is not <type>'s 0x… (another type or version)".
std::string fingerprintMismatch(const lcm::ReceiveBuffer& rbuf, int64_t expected, const char* type_name);

class LcmNode {
 public:
  /// `url` "" means LCM's default (LCM_DEFAULT_URL, else udpm://239.255.76.67:7667?ttl=0).
  /// `channel_prefix` "" means none (one vehicle); else a vehicle's prefix (channels::prefixProblem
  /// refuses it: std::invalid_argument). Throws std::runtime_error when LCM cannot be initialised
  /// (bad URL, no multicast route).
  LcmNode(std::string name, const std::string& url, std::string channel_prefix = "");
  ~LcmNode();
  LcmNode(const LcmNode&) = delete;
  LcmNode& operator=(const LcmNode&) = delete;

  const std::string& name() const { return name_; }
  const std::string& url() const { return url_; }
  /// The vehicle prefix of this node's channels ("" for none).
  const std::string& channelPrefix() const { return prefix_; }
  /// The name on the wire of `channel` for this node: channels::prefixed(channel, channelPrefix()).
  template <class T>
  std::string wireName(channels::Channel<T> channel) const {
    return channels::prefixed(channel, prefix_);
  }
  /// The random instance id stamped into the `sender_id` of every message this node publishes.
  int64_t instanceId() const { return instance_id_; }
  /// How long after its first publication on a channel of its own (from spin()) a node that hears
  /// an older publisher there takes itself for the second instance and stops: longer than
  /// PublisherWatch::kConfirmMessages of the processes' wall-clock heartbeats (1 s by default), so
  /// an idle first instance is heard.
  static constexpr double kSecondInstanceWindow_s = 5.0;
  /// Non-empty when the node stopped because another process already publishes one of its
  /// channels (what it heard): ProcessMain exits with kExitSecondInstance.
  const std::string& secondInstance() const { return second_instance_; }
  const PublisherWatch& publishers() const { return watch_; }
  lcm::LCM& lcm() { return *lcm_; }

  /// Messages LCM queues per subscription before it drops (LCM's default is 30).
  static constexpr int kQueueCapacity = 10000;
  /// Largest message published or accepted [bytes] (256 KiB: far above any meshnav message, far
  /// below what LCM's udpm receive buffer drops silently).
  static constexpr size_t kMaxMessageBytes = 256 * 1024;

  /// Raw subscription (channel is a regex, as in LCM): the callback gets the undecoded bytes.
  using RawHandler = std::function<void(const lcm::ReceiveBuffer& rbuf, const std::string& channel)>;
  void subscribeRaw(const std::string& channel_regex, RawHandler fn);

  /// Typed subscription to `channel`: each message decoded (decode failures reported and counted)
  /// and, for a plain struct, converted with fromLcm (which validates: NaN, unknown codes →
  /// "<CHANNEL>:invalid_message"). The handler takes the channel's type, nothing else: a
  /// subscription with another type does not compile.
  template <class T>
  void subscribe(channels::Channel<T> channel, std::type_identity_t<std::function<void(const T&)>> fn) {
    subscribeAs<T>(prefix_, channel, std::move(fn));
  }
  /// As subscribe, on vehicle `prefix`'s channel (channels::prefixed(channel, prefix)) whatever this
  /// node's own prefix: one node that serves several vehicles on one bus (the fleet's calibrator).
  template <class T>
  void subscribeAs(const std::string& prefix, channels::Channel<T> channel,
                   std::type_identity_t<std::function<void(const T&)>> fn) {
    const std::string wire = channels::prefixed(channel, prefix);
    watch<T>(channel, wire);
    subscribeRaw(wire, [this, fn](const lcm::ReceiveBuffer& rbuf, const std::string& ch) {
      WireType<T> msg;
      if (!decode(rbuf, ch, msg)) return;
      handled(ch, [&] { fn(fromWire<T>(msg)); });
    });
  }

  /// As subscribe, with the wall time [µs] at which LCM received the message (taken by LCM's
  /// receive thread, so it does not include the time the message waited in the queue).
  template <class T>
  void subscribeStamped(channels::Channel<T> channel,
                        std::type_identity_t<std::function<void(const T&, int64_t recv_utime)>> fn) {
    watch<T>(channel, wireName(channel));
    subscribeRaw(wireName(channel), [this, fn](const lcm::ReceiveBuffer& rbuf, const std::string& ch) {
      WireType<T> msg;
      if (!decode(rbuf, ch, msg)) return;
      handled(ch, [&] { fn(fromWire<T>(msg), rbuf.recv_utime); });
    });
  }

  /// Publishes `value` (of the channel's type only) on `channel`, converted with toLcm for a plain
  /// struct. False when it is not sent (too large: "<CHANNEL>:oversized_publish"; LCM error).
  template <class T>
  bool publish(channels::Channel<T> channel, const std::type_identity_t<T>& value) {
    return publishAs<T>(prefix_, channel, value);
  }
  /// As publish, on vehicle `prefix`'s channel whatever this node's own prefix.
  template <class T>
  bool publishAs(const std::string& prefix, channels::Channel<T> channel, const std::type_identity_t<T>& value) {
    if (!second_instance_.empty()) return false;  // it yields the channel: nothing more from it
    const std::string wire = channels::prefixed(channel, prefix);
    if (serving_ && !watch_.published(wire)) watchOwn<T>(channel, wire);
    auto msg = toWire(value);
    msg.sender_id = instance_id_;
    return publishWire(wire, msg);
  }

  /// Calls `fn` every `period` of wall time from spin() (the process heartbeat / status).
  void setHeartbeat(Duration period, std::function<void()> fn);

  /// Handles messages until StopSignal or requestStop(), or until `until()` returns true (checked
  /// after every handled message and at least every 100 ms). Returns 0, or 1 after an LCM error.
  int spin(const std::function<bool()>& until = {});
  /// spin() over several nodes (one per LCM bus) from one thread: waits on every node's descriptor
  /// and handles the ready ones, runs each node's due heartbeat; stops on StopSignal, when any
  /// node's stop was requested (a second instance included) or when `until()` returns true
  /// (checked at least every 100 ms). Returns 0, or 1 after an LCM error.
  /// A node given more than once (vehicles sharing a bus) is served once.
  static int spinAll(const std::vector<LcmNode*>& nodes, const std::function<bool()>& until = {});
  /// Handles at most one batch of messages, waiting up to `timeout_ms`; runs a due heartbeat.
  /// Returns > 0 when something was handled, 0 on timeout, < 0 on an LCM error.
  int spinOnce(int timeout_ms);
  /// Waits until a message arrives on `channel` (a heartbeat, typically; with a channel prefix,
  /// channels::prefixedName(channel, prefix): this vehicle's), a stop is requested or `timeout`
  /// passes (≤ 0: no limit). Returns true when the message was seen. A node with no subscription
  /// and no heartbeat on udpm (a bridge) waits on a temporary LCM instance, so that its own never
  /// starts receiving the bus's traffic; otherwise the node's subscriptions and heartbeat are
  /// served meanwhile.
  bool waitForMessage(const std::string& channel, Duration timeout);
  /// The same, for a message that `accept` (its encoded bytes) says yes to; the others are skipped.
  bool waitForMessage(const std::string& channel, Duration timeout,
                      const std::function<bool(const void* data, size_t size)>& accept);

  void requestStop() { stop_ = true; }
  bool stopRequested() const;

  /// Wall time spent in the handlers of one channel (and in "heartbeat"): what a message costs the
  /// process once it is handled, apart from its wait for a core.
  struct HandlerTime {
    int64_t n = 0;
    double total_us = 0.0, max_us = 0.0;
    int64_t over_1ms = 0;  ///< handler calls longer than 1 ms
  };
  const std::map<std::string, HandlerTime>& handlerTimes() const { return handler_times_; }
  /// One line: per channel n, mean, max and calls over 1 ms (ProcessMain logs it at the exit).
  std::string handlerTimeSummary() const;

  Diagnostics& diagnostics() { return diag_; }
  /// Messages received and decoded per channel (typed subscriptions).
  std::map<std::string, int64_t> receivedCounts() const { return received_; }
  int64_t received(const std::string& channel) const;

 private:
  template <class Msg>
  bool publishWire(const std::string& channel, const Msg& msg) {
    if (const int64_t size = msg.getEncodedSize(); size < 0 || static_cast<size_t>(size) > kMaxMessageBytes) {
      diag_.report(channel + ":oversized_publish", "publish on " + channel + ": " + std::to_string(size) +
                                                       " bytes is above the limit of " +
                                                       std::to_string(kMaxMessageBytes) + "; not sent");
      return false;
    }
    const int rc = lcm_->publish(channel, &msg);
    if (rc != 0) diag_.report("lcm:publish_error", "publish on " + channel + " failed");
    return rc == 0;
  }

  template <class Msg>
  bool decode(const lcm::ReceiveBuffer& rbuf, const std::string& ch, Msg& msg) {
    if (!sizeOk(rbuf, ch)) return false;
    int rc = -1;
    bool older = false;
    std::string what = "not a valid " + std::string(Msg::getTypeName());
    try {
      rc = decodeAnyVersion(rbuf.data, rbuf.data_size, msg, &older);
    } catch (const std::exception& e) {  // e.g. a corrupted length field
      what += std::string(": ") + e.what();
      rc = -1;
    }
    if (rc < 0) {
      if (const std::string fp = fingerprintMismatch(rbuf, Msg::getHash(), Msg::getTypeName()); !fp.empty()) {
        diag_.report(ch + ":decode_error", "channel " + ch + ": dropped a message (" +
                                               std::to_string(rbuf.data_size) + " bytes): " + fp);
        return false;
      }
      diag_.report(ch + ":decode_error", "channel " + ch + ": dropped a malformed message (" +
                                             std::to_string(rbuf.data_size) + " bytes, " + what + ")");
      return false;
    }
    if (older) diag_.count(ch + ":older_version");
    if (!watch_.accepts(ch, msg.sender_id)) return false;  // a second publisher's: counted by the watch
    ++received_[ch];
    return true;
  }
  /// Watches the publishers of `channel` (a channel of one publisher, once): a raw subscription,
  /// made before any typed one of the channel, that decodes and checks each message (a malformed
  /// or implausible one is left to the typed subscription to count) and hands its sender to the
  /// PublisherWatch.
  template <class T>
  void watch(channels::Channel<T> typed, const std::string& channel) {
    if (!channels::hasOnePublisher(typed.name) || !watched_.insert(channel).second) return;
    subscribeRaw(channel, [this](const lcm::ReceiveBuffer& rbuf, const std::string& ch) {
      if (rbuf.data_size > kMaxMessageBytes) return;
      WireType<T> msg;
      try {
        if (decodeAnyVersion(rbuf.data, rbuf.data_size, msg) < 0) return;
        (void)fromWire<T>(msg);  // the plausibility checks: a corrupted message is no publisher's
      } catch (const std::exception&) {
        return;
      }
      if (!watch_.observe(ch, msg.sender_id, rbuf.recv_utime)) onSecondPublisher(ch, msg.sender_id);
    });
  }
  /// A channel this node publishes, from inside spin() (a process that serves a loop; a bridge
  /// that only publishes never handles its own messages, so it does not watch them): every other
  /// sender on it is a second publisher. The first one starts the kSecondInstanceWindow_s.
  template <class T>
  void watchOwn(channels::Channel<T> channel, const std::string& wire) {
    watch_.markPublished(wire);
    if (announced_wall_us_ == 0) announced_wall_us_ = replay::wallUtimeNow();
    watch<T>(channel, wire);
  }
  /// A second publisher's message on `channel`: on a channel of this node, from an instance that
  /// started before it, within kSecondInstanceWindow_s of its start, this node is the second
  /// instance and stops.
  void onSecondPublisher(const std::string& channel, int64_t sender);
  void guarded(const std::string& ch, const std::function<void()>& body);
  /// guarded(), timed into handlerTimes(): a typed handler or the heartbeat.
  void handled(const std::string& ch, const std::function<void()>& body);
  /// False (counted "<CHANNEL>:oversized") for a message above kMaxMessageBytes.
  bool sizeOk(const lcm::ReceiveBuffer& rbuf, const std::string& ch);
  void runHeartbeatIfDue();

  struct RawSub {
    LcmNode* node;
    RawHandler fn;
  };
  static void dispatchRaw(const lcm::ReceiveBuffer* rbuf, const std::string& channel, RawSub* sub);

  std::string name_;
  std::string url_;
  std::string prefix_;  ///< vehicle prefix of the typed channels ("" none)
  int64_t instance_id_;
  int64_t announced_wall_us_ = 0;  ///< first publication on a watched channel of its own (0: none yet)
  bool serving_ = false;           ///< spin() was called: the node handles what it receives
  std::string second_instance_;
  std::set<std::string> watched_;
  std::unique_ptr<lcm::LCM> lcm_;
  std::vector<std::unique_ptr<RawSub>> subs_;
  Diagnostics diag_;
  PublisherWatch watch_{instance_id_, diag_};
  std::map<std::string, int64_t> received_;
  std::map<std::string, HandlerTime> handler_times_;
  bool stop_ = false;
  Duration heartbeat_period_{0};
  std::function<void()> heartbeat_;
  int64_t next_heartbeat_us_ = 0;
};

/// The LCM URL a process uses: `--lcm-url` if given, else LCM_DEFAULT_URL, else LCM's default.
std::string resolveLcmUrl(const std::string& cli_value);

/// Receive buffer every process asks for on udpm unless its URL says `recv_buf_size` [bytes]. The
/// kernel's default (about 208 kB) holds about 0.1 s of a 10× replay with POSE and POSE_SMOOTHED
/// (4000 messages/s): a subscriber held up longer lost messages (the logger an ANCHOR_INIT in
/// integration.flyby_auto_smoothed_lcm). The kernel caps it at net.core.rmem_max.
inline constexpr int kUdpmReceiveBufferBytes = 4 * 1024 * 1024;

/// `url` with `recv_buf_size=kUdpmReceiveBufferBytes` added when it is udpm without one.
std::string withReceiveBuffer(const std::string& url);

}  // namespace meshnav::transport
