/// meshnav_lcmlog_dump: prints every event of an LCM log as `channel,recv_utime,t` (t: the data time
/// of a POSE, ANCHORS or ANCHOR_INIT decoded with the project's converters, in seconds; empty for
/// other channels or an event that does not decode), then `events,N` and `bad,N`. For the logger's
/// restart test (logger_restart_test.py).
///   meshnav_lcmlog_dump FILE
#include <cstdio>
#include <string>

#include "common/cli.h"
#include "transport/channels.h"
#include "transport/input_journal.h"

int main(int argc, char** argv) {
  using namespace meshnav;
  Cli cli("meshnav_lcmlog_dump", "Prints the events of an LCM log: channel,recv_utime,t.");
  std::string path;
  cli.app().add_option("file", path, "the LCM log")->type_name("FILE")->required();
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  Diagnostics diag;
  const int64_t n = transport::InputJournal::read(path, [&](const std::string& ch, const lcm::ReceiveBuffer& rbuf) {
    std::string t;
    if (ch == channels::kPose.name) {
      PoseEstimate e;
      if (transport::InputJournal::decode(rbuf, channels::kPose, e, diag)) t = formatSeconds(e.t);
    } else if (ch == channels::kAnchors.name) {
      std::vector<AnchorEstimate> a;
      if (transport::InputJournal::decode(rbuf, channels::kAnchors, a, diag) && !a.empty()) t = formatSeconds(a.front().t);
    } else if (ch == channels::kAnchorInit.name) {
      AnchorInit a;
      if (transport::InputJournal::decode(rbuf, channels::kAnchorInit, a, diag)) t = formatSeconds(a.t);
    }
    std::printf("%s,%lld,%s\n", ch.c_str(), static_cast<long long>(rbuf.recv_utime), t.c_str());
  });
  std::printf("events,%lld\nbad,%lld\n", static_cast<long long>(n), static_cast<long long>(diag.total()));
  return 0;
}
