#include "transport/lcm_node.h"

#include <poll.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "transport/replay/clock.h"
#include "transport/stop_signal.h"

namespace meshnav::transport {

const std::vector<RetiredFingerprint>& retiredFingerprints() {
  // Computed with the generated headers of the version named (lcm-gen's getHash()).
  static const std::vector<RetiredFingerprint> kRetired = {
      {static_cast<int64_t>(0xa4a10701fd07c42dULL),
       "anchor_init_t version 1 (before issue 10: without the joint covariance of position and gammas)"},
      {static_cast<int64_t>(0xcacef84225dccaafULL),
       "estimator_cmd_t version 1 (before issue 10: its anchor_init_t without the joint covariance)"},
  };
  return kRetired;
}

std::string fingerprintMismatch(const lcm::ReceiveBuffer& rbuf, int64_t expected, const char* type_name) {
  if (rbuf.data_size < 8) return "";
  const auto found = static_cast<uint64_t>(encodedFingerprint(rbuf.data, rbuf.data_size));
  if (static_cast<int64_t>(found) == expected) return "";
  for (const RetiredFingerprint& r : retiredFingerprints())
    if (static_cast<int64_t>(found) == r.hash)
      return std::string("an older message version, ") + r.what + ", which this build does not read as " +
             type_name + " (re-record, or replay the dataset instead of the old log)";
  char buf[160];
  std::snprintf(buf, sizeof buf, "fingerprint 0x%016llx is not %s's 0x%016llx (another type or version)",
                static_cast<unsigned long long>(found), type_name, static_cast<unsigned long long>(expected));
  return buf;
}

std::string resolveLcmUrl(const std::string& cli_value) {
  if (!cli_value.empty()) return cli_value;
  if (const char* env = std::getenv("LCM_DEFAULT_URL"); env && *env) return env;
  return "udpm://239.255.76.67:7667?ttl=0";
}

std::string withReceiveBuffer(const std::string& url) {
  if (url.rfind("udpm://", 0) != 0 || url.find("recv_buf_size") != std::string::npos) return url;
  return url + (url.find('?') == std::string::npos ? "?" : "&") + "recv_buf_size=" +
         std::to_string(kUdpmReceiveBufferBytes);
}

LcmNode::LcmNode(std::string name, const std::string& url, std::string channel_prefix)
    : name_(std::move(name)),
      url_(withReceiveBuffer(resolveLcmUrl(url))),
      prefix_(std::move(channel_prefix)),
      instance_id_(PublisherWatch::newInstanceId(replay::wallUtimeNow())) {
  if (!prefix_.empty())
    if (const std::string why = channels::prefixProblem(prefix_); !why.empty())
      throw std::invalid_argument(name_ + ": channel prefix " + why);
  lcm_ = std::make_unique<lcm::LCM>(url_);
  if (!lcm_->good())
    throw std::runtime_error(name_ + ": cannot initialise LCM with URL '" + url_ +
                             "' (for udpm on loopback: ip link set lo multicast on; "
                             "ip route add 224.0.0.0/4 dev lo)");
  spdlog::debug("{}: LCM on {}, instance {}", name_, url_, PublisherWatch::format(instance_id_));
}

void LcmNode::onSecondPublisher(const std::string& channel, int64_t sender) {
  if (!second_instance_.empty() || !watch_.published(channel)) return;
  // The one that started later yields; one that has run for a while is never stopped by another.
  if (!PublisherWatch::startedBefore(sender, instance_id_)) return;
  const double age_s = static_cast<double>(replay::wallUtimeNow() - announced_wall_us_) * 1e-6;
  if (age_s > kSecondInstanceWindow_s) return;  // counted by the watch, not refused
  second_instance_ = "channel " + channel + " is published by instance " + PublisherWatch::format(sender) +
                     ", which started before this one (" + PublisherWatch::format(instance_id_) + ")";
  spdlog::error("{}: another instance already runs on this LCM network ({}; {}): stopping, the other keeps the "
                "channel. Stop the other launch first, or give this one another --lcm-url.",
                name_, url_, second_instance_);
  requestStop();
}

LcmNode::~LcmNode() = default;

void LcmNode::dispatchRaw(const lcm::ReceiveBuffer* rbuf, const std::string& channel, RawSub* sub) {
  sub->node->guarded(channel, [&] { sub->fn(*rbuf, channel); });
}

void LcmNode::subscribeRaw(const std::string& channel_regex, RawHandler fn) {
  subs_.push_back(std::make_unique<RawSub>(RawSub{this, std::move(fn)}));
  lcm::Subscription* sub = lcm_->subscribeFunction(channel_regex, &LcmNode::dispatchRaw, subs_.back().get());
  // LCM drops messages of a subscription whose queue is full (default 30): a burst (a replay at
  // high speed, lcm-logplayer catching up) must not lose data for a process that is briefly busy.
  if (sub) sub->setQueueCapacity(kQueueCapacity);
}

void LcmNode::handled(const std::string& ch, const std::function<void()>& body) {
  const auto start = std::chrono::steady_clock::now();
  guarded(ch, body);
  const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  HandlerTime& h = handler_times_[ch];
  ++h.n;
  h.total_us += us;
  h.max_us = std::max(h.max_us, us);
  h.over_1ms += us > 1000.0;
}

void LcmNode::guarded(const std::string& ch, const std::function<void()>& body) {
  try {
    body();
  } catch (const InvalidMessage& e) {
    diag_.report(ch + ":invalid_message", "channel " + ch + ": dropped an invalid message (" + e.what() + ")");
  } catch (const std::exception& e) {
    diag_.report(ch + ":handler_error", "channel " + ch + ": handler failed: " + e.what());
  }
}

std::string LcmNode::handlerTimeSummary() const {
  std::string out;
  for (const auto& [ch, h] : handler_times_)
    out += fmt::format("{}{} n {} mean {:.0f} µs max {:.1f} ms >1 ms {}", out.empty() ? "" : "; ", ch, h.n,
                       h.total_us / static_cast<double>(std::max<int64_t>(1, h.n)), h.max_us / 1000.0, h.over_1ms);
  return out;
}

void LcmNode::setHeartbeat(Duration period, std::function<void()> fn) {
  heartbeat_period_ = period;
  heartbeat_ = std::move(fn);
  next_heartbeat_us_ = replay::wallUtimeNow();  // first beat at once: subscribers see us early
}

void LcmNode::runHeartbeatIfDue() {
  if (!heartbeat_ || heartbeat_period_.us <= 0) return;
  const int64_t now = replay::wallUtimeNow();
  if (now < next_heartbeat_us_) return;
  next_heartbeat_us_ = now + heartbeat_period_.us;
  handled("heartbeat", heartbeat_);
}

bool LcmNode::sizeOk(const lcm::ReceiveBuffer& rbuf, const std::string& ch) {
  if (rbuf.data_size <= kMaxMessageBytes) return true;
  diag_.report(ch + ":oversized", "channel " + ch + ": dropped a message of " + std::to_string(rbuf.data_size) +
                                      " bytes (limit " + std::to_string(kMaxMessageBytes) + ")");
  return false;
}

bool LcmNode::stopRequested() const { return stop_ || StopSignal::requested(); }

int64_t LcmNode::received(const std::string& channel) const {
  auto it = received_.find(channel);
  return it == received_.end() ? 0 : it->second;
}

int LcmNode::spinOnce(int timeout_ms) {
  if (heartbeat_ && heartbeat_period_.us > 0) {
    const int64_t to_beat_ms = (next_heartbeat_us_ - replay::wallUtimeNow()) / 1000;
    timeout_ms = static_cast<int>(std::max<int64_t>(0, std::min<int64_t>(timeout_ms, to_beat_ms)));
  }
  const int rc = lcm_->handleTimeout(timeout_ms);
  runHeartbeatIfDue();
  if (rc < 0 && (errno == EINTR || stopRequested())) return 0;  // interrupted by a signal
  return rc;
}

int LcmNode::spin(const std::function<bool()>& until) {
  serving_ = true;
  runHeartbeatIfDue();
  while (!stopRequested()) {
    if (until && until()) break;
    const int rc = spinOnce(100);
    if (rc < 0) {
      spdlog::error("{}: LCM handle failed (URL {})", name_, url_);
      return 1;
    }
  }
  return 0;
}

int LcmNode::spinAll(const std::vector<LcmNode*>& given, const std::function<bool()>& until) {
  // Each node once: a fleet on one bus names the same node for every vehicle.
  std::vector<LcmNode*> nodes;
  for (LcmNode* n : given)
    if (std::find(nodes.begin(), nodes.end(), n) == nodes.end()) nodes.push_back(n);
  if (nodes.size() == 1) return nodes.front()->spin(until);
  for (LcmNode* n : nodes) {
    n->serving_ = true;
    n->runHeartbeatIfDue();
  }
  std::vector<pollfd> fds;
  for (LcmNode* n : nodes) fds.push_back({n->lcm().getFileno(), POLLIN, 0});
  const auto stopped = [&] { return std::any_of(nodes.begin(), nodes.end(), [](LcmNode* n) { return n->stopRequested(); }); };
  while (!stopped() && !(until && until())) {
    // Wake for the next heartbeat of any node, at the latest after 100 ms (the stop check).
    int64_t timeout_ms = 100;
    for (LcmNode* n : nodes)
      if (n->heartbeat_ && n->heartbeat_period_.us > 0)
        timeout_ms = std::min<int64_t>(timeout_ms, (n->next_heartbeat_us_ - replay::wallUtimeNow()) / 1000);
    const int ready = ::poll(fds.data(), fds.size(), static_cast<int>(std::max<int64_t>(0, timeout_ms)));
    if (ready < 0 && errno != EINTR) {
      spdlog::error("{}: poll on {} LCM buses failed", nodes.front()->name_, nodes.size());
      return 1;
    }
    for (size_t i = 0; i < fds.size(); ++i) {
      if (ready > 0 && (fds[i].revents & POLLIN) && nodes[i]->spinOnce(0) < 0 && !nodes[i]->stopRequested()) {
        spdlog::error("{}: LCM handle failed (URL {})", nodes[i]->name_, nodes[i]->url_);
        return 1;
      }
      nodes[i]->runHeartbeatIfDue();
    }
  }
  return 0;
}

bool LcmNode::waitForMessage(const std::string& channel, Duration timeout) {
  return waitForMessage(channel, timeout, nullptr);
}

bool LcmNode::waitForMessage(const std::string& channel, Duration timeout,
                             const std::function<bool(const void* data, size_t size)>& accept) {
  struct Wait {
    const std::function<bool(const void*, size_t)>* accept;
    bool seen = false;
  } wait{&accept};
  const std::string wire = channels::prefixedName(channel, prefix_);
  auto flag = +[](const lcm::ReceiveBuffer* rbuf, const std::string&, Wait* w) {
    if (!*w->accept || (*w->accept)(rbuf->data, rbuf->data_size)) w->seen = true;
  };
  bool& seen = wait.seen;
  const int64_t deadline = timeout.us > 0 ? replay::wallUtimeNow() + timeout.us : 0;
  // A node that only publishes (a bridge: no subscription, no heartbeat) waits on a second LCM
  // instance that ends with the wait. udpm starts an instance's receive thread at its first
  // subscription and then reads every datagram of the bus until the instance ends: on the node's
  // own instance a bridge would receive its whole vehicle's traffic for the rest of its run
  // (docs/fleet.md, "A bus per vehicle, measured"). memq:// is one bus per instance, so it keeps
  // the node's own.
  if (subs_.empty() && !heartbeat_ && url_.rfind("udpm://", 0) == 0) {
    lcm::LCM waiter(url_);
    if (!waiter.good()) throw std::runtime_error(name_ + ": cannot initialise LCM with URL '" + url_ + "' to wait");
    waiter.subscribeFunction(wire, flag, &wait);
    while (!seen && !stopRequested()) {
      if (deadline && replay::wallUtimeNow() >= deadline) break;
      const int rc = waiter.handleTimeout(100);
      if (rc < 0 && errno != EINTR && !stopRequested()) break;
    }
    return seen;
  }
  lcm::Subscription* sub = lcm_->subscribeFunction(wire, flag, &wait);
  while (!seen && !stopRequested()) {
    if (deadline && replay::wallUtimeNow() >= deadline) break;
    if (spinOnce(100) < 0) break;
  }
  lcm_->unsubscribe(sub);
  return seen;
}

}  // namespace meshnav::transport
