/// meshnav_lcm_probe: receives IMU, RANGE, POSE (and counts every other channel) and writes what
/// `./meshnav bench lcm` reports (scripts/bench_lcm.sh): IMU → POSE and RANGE → POSE latency
/// (median, p99, max) from its own receive times, and messages per second per channel
/// (transport/latency_recorder.h says what each figure is). It runs until SIGINT/SIGTERM or
/// --duration, then writes --out (YAML) and prints it.
#include <fstream>
#include <iostream>
#include <sstream>

#include "common/cli.h"
#include "transport/channels.h"
#include "transport/latency_recorder.h"
#include "transport/lcm_node.h"
#include "transport/stop_signal.h"

int main(int argc, char** argv) {
  using namespace meshnav;
  using namespace meshnav::transport;
  Cli cli("meshnav_lcm_probe",
          "Measures IMU -> POSE and RANGE -> POSE latency (median, p99, max, from this process's receive times) and "
          "messages per second per channel over LCM, until SIGINT/SIGTERM or --duration; writes --out (YAML).");
  std::string out, url;
  double duration_s = 0.0;
  cli.optional("out", out, "where to write the figures (YAML)")->type_name("FILE")->required();
  cli.option("duration", duration_s, "stop after S seconds of wall time (0: at SIGINT/SIGTERM) [s]")
      ->type_name("S")
      ->check(CLI::NonNegativeNumber);
  cli.optional("lcm-url", url, "LCM provider (default: LCM_DEFAULT_URL)")->type_name("URL");
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  StopSignal::install();
  LatencyRecorder rec;
  try {
    LcmNode node("lcm_probe", url);
    node.subscribeStamped(channels::kImu, [&](const ImuSample& s, int64_t recv) { rec.onImu(s.t.us, recv); });
    node.subscribeStamped(channels::kRange, [&](const RangeSample& s, int64_t recv) { rec.onRange(s.t.us, recv); });
    node.subscribeStamped(channels::kPose, [&](const PoseEstimate& p, int64_t recv) { rec.onPose(p.t.us, recv); });
    node.subscribeRaw("^(?!IMU$|RANGE$|POSE$).*", [&](const lcm::ReceiveBuffer& rbuf, const std::string& ch) {
      rec.onOther(ch, rbuf.recv_utime);
    });
    std::cout << "lcm_probe: listening on " << node.url() << std::endl;
    const auto start = std::chrono::steady_clock::now();
    node.spin([&] {
      return duration_s > 0.0 &&
             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= duration_s;
    });
  } catch (const std::exception& ex) {
    std::cerr << "meshnav_lcm_probe: " << ex.what() << "\n";
    return 1;
  }
  std::ostringstream y;
  auto stats = [&](const char* name, const LatencyStats& s) {
    y << name << ": {n: " << s.n << ", median_us: " << s.median_us << ", p99_us: " << s.p99_us
      << ", max_us: " << s.max_us << "}\n";
  };
  stats("imu_to_pose", rec.imuToPose());
  stats("range_to_pose", rec.rangeToPose());
  y << "ranges_unanswered: " << rec.rangesUnanswered() << "\nchannels:\n";
  const auto rates = rec.ratesHz();
  for (const auto& [ch, n] : rec.counts()) y << "  " << ch << ": {messages: " << n << ", per_s: " << rates.at(ch) << "}\n";
  std::ofstream f(out);
  f << y.str();
  if (!f) {
    std::cerr << "meshnav_lcm_probe: cannot write " << out << "\n";
    return 1;
  }
  std::cout << y.str() << std::flush;
  return 0;
}
