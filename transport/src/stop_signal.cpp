#include "transport/stop_signal.h"

#include <atomic>
#include <csignal>

namespace meshnav::transport {
namespace {

std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "signal handler needs a lock-free flag");

extern "C" void onStopSignal(int sig) {
  if (g_stop.exchange(true)) std::signal(sig, SIG_DFL);  // second signal: default action next time
}

}  // namespace

void StopSignal::install() {
  struct sigaction sa {};
  sa.sa_handler = onStopSignal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: blocking calls return EINTR and the loop sees the flag
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}
bool StopSignal::requested() { return g_stop.load(); }
void StopSignal::request() { g_stop.store(true); }
void StopSignal::reset() { g_stop.store(false); }

}  // namespace meshnav::transport
