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
/// "<CHANNEL>:oversized_publish" (a message of ours above it, not sent).
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
#include <string>
#include <type_traits>
#include <vector>

#include "common/diagnostics.h"
#include "common/time.h"
#include "transport/channels.h"
#include "transport/convert.h"

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
  /// Throws std::runtime_error when LCM cannot be initialised (bad URL, no multicast route).
  LcmNode(std::string name, const std::string& url);
  ~LcmNode();
  LcmNode(const LcmNode&) = delete;
  LcmNode& operator=(const LcmNode&) = delete;

  const std::string& name() const { return name_; }
  const std::string& url() const { return url_; }
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
    subscribeRaw(channel.name, [this, fn](const lcm::ReceiveBuffer& rbuf, const std::string& ch) {
      WireType<T> msg;
      if (!decode(rbuf, ch, msg)) return;
      guarded(ch, [&] { fn(fromWire<T>(msg)); });
    });
  }

  /// As subscribe, with the wall time [µs] at which LCM received the message (taken by LCM's
  /// receive thread, so it does not include the time the message waited in the queue).
  template <class T>
  void subscribeStamped(channels::Channel<T> channel,
                        std::type_identity_t<std::function<void(const T&, int64_t recv_utime)>> fn) {
    subscribeRaw(channel.name, [this, fn](const lcm::ReceiveBuffer& rbuf, const std::string& ch) {
      WireType<T> msg;
      if (!decode(rbuf, ch, msg)) return;
      guarded(ch, [&] { fn(fromWire<T>(msg), rbuf.recv_utime); });
    });
  }

  /// Publishes `value` (of the channel's type only) on `channel`, converted with toLcm for a plain
  /// struct. False when it is not sent (too large: "<CHANNEL>:oversized_publish"; LCM error).
  template <class T>
  bool publish(channels::Channel<T> channel, const std::type_identity_t<T>& value) {
    return publishWire(channel.name, toWire(value));
  }

  /// Calls `fn` every `period` of wall time from spin() (the process heartbeat / status).
  void setHeartbeat(Duration period, std::function<void()> fn);

  /// Handles messages until StopSignal or requestStop(), or until `until()` returns true (checked
  /// after every handled message and at least every 100 ms). Returns 0, or 1 after an LCM error.
  int spin(const std::function<bool()>& until = {});
  /// Handles at most one batch of messages, waiting up to `timeout_ms`; runs a due heartbeat.
  /// Returns > 0 when something was handled, 0 on timeout, < 0 on an LCM error.
  int spinOnce(int timeout_ms);
  /// Waits until a message arrives on `channel` (a heartbeat, typically), a stop is requested or
  /// `timeout` passes (≤ 0: no limit). Returns true when the message was seen.
  bool waitForMessage(const std::string& channel, Duration timeout);

  void requestStop() { stop_ = true; }
  bool stopRequested() const;

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
    std::string what = "not a valid " + std::string(Msg::getTypeName());
    try {
      rc = msg.decode(rbuf.data, 0, static_cast<int>(rbuf.data_size));
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
    ++received_[ch];
    return true;
  }
  void guarded(const std::string& ch, const std::function<void()>& body);
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
  std::unique_ptr<lcm::LCM> lcm_;
  std::vector<std::unique_ptr<RawSub>> subs_;
  Diagnostics diag_;
  std::map<std::string, int64_t> received_;
  bool stop_ = false;
  Duration heartbeat_period_{0};
  std::function<void()> heartbeat_;
  int64_t next_heartbeat_us_ = 0;
};

/// The LCM URL a process uses: `--lcm-url` if given, else LCM_DEFAULT_URL, else LCM's default.
std::string resolveLcmUrl(const std::string& cli_value);

}  // namespace meshnav::transport
