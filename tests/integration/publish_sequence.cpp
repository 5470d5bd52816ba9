/// meshnav_publish_sequence: publishes a known sequence of POSE, ANCHORS and ANCHOR_INIT messages at
/// a fixed wall rate and records when each was sent, for the logger's restart test
/// (logger_restart_test.py). POSE number i has data time t = 100 s + i · 10 ms and p_IinG = (i mm, 0, 1);
/// every K-th POSE is followed by an ANCHORS message with anchors 201 and 202 stamped at the same t;
/// the ANCHOR_INITs of --anchor-inits come first, stamped at the first POSE's t.
///   meshnav_publish_sequence --first I --count N --rate HZ [--anchors-every K] [--anchor-inits 101,102]
///                            --record FILE [--lcm-url URL]
/// --record FILE: one line per message sent, `channel,index,wall_utime` (wall_utime read just
/// before publishing, µs since the Unix epoch; index: the POSE number, or the anchor id of an
/// ANCHOR_INIT), flushed at the end.
#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "common/cli.h"
#include "transport/channels.h"
#include "transport/convert.h"

namespace {

int64_t wallUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

meshnav::Timestamp poseTime(int64_t i) { return meshnav::Timestamp{100'000'000 + i * 10'000}; }

}  // namespace

int main(int argc, char** argv) {
  using namespace meshnav;
  Cli cli("meshnav_publish_sequence",
          "Publishes POSE number FIRST..FIRST+N-1 at HZ (t = 100 s + i * 10 ms), an ANCHORS (anchors 201, 202) after "
          "every K-th, and first one ANCHOR_INIT per id of --anchor-inits; records each send in --record.");
  int64_t first = 0, count = 100;
  double rate_hz = 100.0;
  int anchors_every = 10;
  std::vector<int32_t> anchor_inits;
  std::string record_path, url;
  cli.option("first", first, "number of the first POSE")->type_name("I")->check(CLI::NonNegativeNumber);
  cli.option("count", count, "POSE messages")->type_name("N")->check(CLI::NonNegativeNumber);
  cli.option("rate", rate_hz, "POSE messages per second of wall time")->type_name("HZ")->check(CLI::PositiveNumber);
  cli.option("anchors-every", anchors_every, "an ANCHORS message after every K-th POSE")
      ->type_name("K")
      ->check(CLI::PositiveNumber);
  cli.idList("anchor-inits", anchor_inits, "anchor ids of the ANCHOR_INITs sent first");
  cli.optional("record", record_path, "where to record what was sent")->type_name("FILE")->required();
  cli.optional("lcm-url", url, "LCM provider")->type_name("URL");
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  lcm::LCM lcm(url);
  if (!lcm.good()) return 1;
  std::ofstream record(record_path);
  if (!record) {
    std::fprintf(stderr, "%s: cannot write\n", record_path.c_str());
    return 1;
  }
  std::vector<std::string> lines;  // written at the end: the publishing loop does no file I/O
  lines.reserve(static_cast<size_t>(count) * 2 + anchor_inits.size());

  for (int32_t id : anchor_inits) {
    AnchorInit a;
    a.t = poseTime(first);
    a.id = static_cast<SensorId>(id);
    a.p_AinG = {0.1 * id, -0.2, 1.5};
    a.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.01;
    a.biases = {PairBias{100, a.id, 0.1, 1.0, 0.1, 0.02, 0.0}};
    a.n_inliers = 50;
    const auto msg = transport::toLcm(a);
    lines.push_back(std::string(channels::kAnchorInit.name) + "," + std::to_string(id) + "," +
                    std::to_string(wallUtime()));
    lcm.publish(channels::kAnchorInit.name, &msg);
  }
  const auto start = std::chrono::steady_clock::now();
  for (int64_t k = 0; k < count; ++k) {
    std::this_thread::sleep_until(start + std::chrono::microseconds(static_cast<int64_t>(k * 1e6 / rate_hz)));
    const int64_t i = first + k;
    PoseEstimate e;
    e.t = poseTime(i);
    e.p_IinG = {i * 1e-3, 0.0, 1.0};
    e.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.04;
    e.cov_theta_rad2 = Eigen::Matrix3d::Identity() * 1e-4;
    const auto pose = transport::toLcm(e);
    lines.push_back(std::string(channels::kPose.name) + "," + std::to_string(i) + "," +
                    std::to_string(wallUtime()));
    lcm.publish(channels::kPose.name, &pose);
    if (i % anchors_every != 0) continue;
    std::vector<AnchorEstimate> anchors(2);
    for (int j = 0; j < 2; ++j) {
      anchors[j].t = e.t;
      anchors[j].id = static_cast<SensorId>(201 + j);
      anchors[j].p_AinG = {2.0 + j, 3.0, 0.5};
      anchors[j].cov_p_m2 = Eigen::Matrix3d::Identity() * 0.01;
    }
    const auto msg = transport::toLcm(e.t, anchors);
    lines.push_back(std::string(channels::kAnchors.name) + "," + std::to_string(i) + "," +
                    std::to_string(wallUtime()));
    lcm.publish(channels::kAnchors.name, &msg);
  }
  for (const auto& l : lines) record << l << '\n';
  std::printf("published %lld POSE from %lld at %.0f Hz and %zu ANCHOR_INIT\n", static_cast<long long>(count),
              static_cast<long long>(first), rate_hz, anchor_inits.size());
  return record ? 0 : 1;
}
