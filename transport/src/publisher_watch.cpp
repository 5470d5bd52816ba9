#include "transport/publisher_watch.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <random>

namespace meshnav::transport {

std::string PublisherWatch::format(int64_t id) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(id));
  return buf;
}

int64_t PublisherWatch::newInstanceId(int64_t wall_us) {
  std::random_device rd;
  const uint64_t ms = static_cast<uint64_t>(std::max<int64_t>(wall_us, 0) / 1000) & ((uint64_t{1} << 43) - 1);
  const uint64_t id = (ms << 20) | (rd() & 0xfffffu);
  return static_cast<int64_t>(id == 0 ? 1 : id);
}

bool PublisherWatch::observeOwn(const std::string& channel, int64_t sender) {
  if (sender == own_id_) return true;
  ChannelState& st = channels_[channel];
  if (st.rivals.insert(sender).second) {
    const std::string what = "channel " + channel + ": another process publishes it too (instance " + format(sender) +
                             "; this process is " + format(own_id_) +
                             "): a second launch of the same processes, or a log played back with its outputs";
    diag_.report(channel + ":second_publisher", what);
  } else {
    diag_.count(channel + ":second_publisher");
  }
  return false;
}

bool PublisherWatch::confirmed(ChannelState& st, int64_t sender) {
  if (st.confirmed.count(sender) || sender == own_id_) return true;
  // A corrupted message that still decodes carries a random id, once: an id counts as a
  // publisher from its kConfirmMessages-th message on. The candidates of random ids are dropped
  // in bulk so that a flood of them cannot grow the map.
  if (st.candidates.size() >= kMaxCandidates) st.candidates.clear();
  if (++st.candidates[sender] < kConfirmMessages) return false;
  st.candidates.erase(sender);
  st.confirmed.insert(sender);
  return true;
}

bool PublisherWatch::observe(const std::string& channel, int64_t sender, int64_t wall_us) {
  ChannelState& st = channels_[channel];
  if (sender == 0) return true;
  if (!confirmed(st, sender)) return true;  // passes, as every message did before sender ids
  if (published(channel)) return observeOwn(channel, sender);
  SenderState& me = st.senders[sender];  // a std::map: references stay valid on insertion
  const bool is_new = me.order == 0;
  if (is_new) me.order = ++st.next_order;
  me.last_wall_us = wall_us;
  if (st.owner == 0 || st.owner == sender) {
    st.owner = sender;
    return true;
  }
  const SenderState& owner = st.senders[st.owner];
  const bool owner_alive = wall_us - owner.last_wall_us <= static_cast<int64_t>(kLiveness_s * 1e6);
  if (is_new || !owner_alive) {
    // A new sender (a restart: the old one never speaks again), or one whose predecessor has
    // been silent for kLiveness_s (a log played after another, a rival whose owner stopped).
    spdlog::info("channel {}: publisher {} replaces {}{}", channel, format(sender), format(st.owner),
                 is_new ? " (a restart)" : " (silent since)");
    diag_.count(channel + ":publisher_changed");
    st.rivals.erase(sender);
    st.owner = sender;
    return true;
  }
  if (st.rivals.count(sender)) {
    diag_.count(channel + ":second_publisher");
    return false;
  }
  // A replaced sender speaks again while the one that replaced it is alive: two live publishers.
  // The one this receiver heard first keeps the channel (the stream its state was built on).
  const int64_t first = me.order < owner.order ? sender : st.owner;
  const int64_t second = first == sender ? st.owner : sender;
  st.rivals.insert(second);
  st.owner = first;
  diag_.report(channel + ":second_publisher",
               "channel " + channel + ": two processes publish it (instances " + format(first) + " and " +
                   format(second) + "): a second launch of the same processes, or a log played back with its " +
                   "outputs; keeping " + format(first) + " (heard first), dropping the messages of " + format(second));
  return sender == first;
}

bool PublisherWatch::accepts(const std::string& channel, int64_t sender) const {
  if (sender == 0) return true;
  auto it = channels_.find(channel);
  return it == channels_.end() || it->second.rivals.count(sender) == 0;
}

std::map<std::string, std::set<int64_t>> PublisherWatch::secondPublishers() const {
  std::map<std::string, std::set<int64_t>> out;
  for (const auto& [ch, st] : channels_)
    if (!st.rivals.empty()) out[ch] = st.rivals;
  return out;
}

}  // namespace meshnav::transport
