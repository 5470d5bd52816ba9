/// @file bench_transport.cpp
/// @brief What the publisher watch (transport/publisher_watch.h, issue 36) costs per received
/// message: a POSE published and handled over memq:// by an LcmNode's typed subscription (the
/// watch decodes and checks the message, then the typed handler decodes it again), against the
/// same message handled as before the watch (one raw subscription: decode, convert). Run in one
/// process, read as the ratio of the medians:
///   ./meshnav bench transport
#include <benchmark/benchmark.h>

#include "transport/channels.h"
#include "transport/lcm_node.h"

using namespace meshnav;
using namespace meshnav::transport;

namespace {

PoseEstimate pose() {
  PoseEstimate e;
  e.t = Timestamp{1'000'000};
  e.p_IinG = Eigen::Vector3d(1.0, 2.0, 3.0);
  e.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.01;
  e.cov_v = Eigen::Matrix3d::Identity() * 0.01;
  e.cov_theta_rad2 = Eigen::Matrix3d::Identity() * 1e-4;
  return e;
}

/// Publishes one POSE and handles it, `state.iterations()` times.
void run(benchmark::State& state, LcmNode& node, const int64_t& handled) {
  const PoseEstimate e = pose();
  for (auto _ : state) {
    node.publish(channels::kPose, e);
    while (node.spinOnce(0) > 0) {
    }
  }
  if (handled != state.iterations()) state.SkipWithError("a message was not handled");
}

/// The typed subscription with the publisher watch (the published channel is watched too).
void BM_PoseWatched(benchmark::State& state) {
  LcmNode node("bench", "memq://");
  int64_t handled = 0;
  node.subscribe(channels::kPose, [&](const PoseEstimate& p) { handled += p.t.us > 0; });
  node.spin([] { return true; });  // a serving node: its own channel is watched as well
  run(state, node, handled);
}
BENCHMARK(BM_PoseWatched);

/// The same message handled as before the watch: one decode and one conversion per message.
void BM_PoseUnwatched(benchmark::State& state) {
  LcmNode node("bench", "memq://");
  int64_t handled = 0;
  node.subscribeRaw(channels::kPose.name, [&](const lcm::ReceiveBuffer& rb, const std::string&) {
    pose_t m;
    if (m.decode(rb.data, 0, static_cast<int>(rb.data_size)) < 0) return;
    handled += fromLcm(m).t.us > 0;
  });
  run(state, node, handled);
}
BENCHMARK(BM_PoseUnwatched);

}  // namespace

BENCHMARK_MAIN();
