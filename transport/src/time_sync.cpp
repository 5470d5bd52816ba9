#include "transport/time_sync.h"

#include <spdlog/spdlog.h>

#include "meshnav/time_sync_t.hpp"
#include "transport/channels.h"
#include "transport/replay/clock.h"

namespace meshnav::transport {

void serveTimeSync(LcmNode& node) {
  node.subscribeStamped(
      channels::kTimeSyncRequest, [&node](const meshnav::time_sync_t& req, int64_t recv_utime) {
        meshnav::time_sync_t reply = req;
        reply.t_receive = recv_utime;
        reply.t_reply = replay::wallUtimeNow();
        node.publish(channels::kTimeSync, reply);
      });
}

TimeSyncClient::TimeSyncClient(LcmNode& node, std::string client, Duration injected_offset,
                               ClockOffsetOptions options)
    : node_(node), client_(std::move(client)), injected_(injected_offset), estimator_(options) {
  node_.subscribeStamped(
      channels::kTimeSync, [this](const meshnav::time_sync_t& r, int64_t recv_utime) {
        if (r.client != client_) return;  // another client's reply
        if (r.seq < 1 || r.seq > seq_) {
          node_.diagnostics().report("time_sync:bad_exchange", "TIME_SYNC reply to request " + std::to_string(r.seq) +
                                                                   ", which was never sent");
          return;
        }
        ClockExchange e{r.utime, r.t_receive, r.t_reply, recv_utime + injected_.us};
        const bool had = estimator_.offset().has_value();
        if (estimator_.add(e, node_.diagnostics()) && !had)
          spdlog::info("time sync: clock offset to the reference {:+.1f} ms (± {:.1f} ms)", *offset() / 1e3,
                       *errorBound() / 1e3);
      });
}

int64_t TimeSyncClient::localNow() const { return replay::wallUtimeNow() + injected_.us; }

void TimeSyncClient::request() {
  meshnav::time_sync_t req{};
  req.utime = localNow();
  req.client = client_;
  req.seq = ++seq_;
  last_request_wall_ = replay::wallUtimeNow();
  node_.publish(channels::kTimeSyncRequest, req);
}

void TimeSyncClient::poll(Duration period) {
  if (replay::wallUtimeNow() - last_request_wall_ >= period.us) request();
}

bool TimeSyncClient::synchronize(int n, Duration gap, Duration timeout) {
  const int64_t start = replay::wallUtimeNow();
  int sent = 0;
  while (!node_.stopRequested() && replay::wallUtimeNow() - start < timeout.us) {
    if (sent < n && replay::wallUtimeNow() - last_request_wall_ >= gap.us) {
      request();
      ++sent;
    }
    if (sent >= n && offset()) break;
    node_.spinOnce(10);
  }
  // Replies still in flight are taken later (poll + spinOnce during the run).
  return offset().has_value();
}

Timestamp TimeSyncClient::toReference(Timestamp local) {
  if (const auto o = offset()) return Timestamp{local.us + *o};
  node_.diagnostics().count("time_sync:unsynchronized");
  return local;
}

}  // namespace meshnav::transport
