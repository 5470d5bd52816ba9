/// meshnav_netem_switch: the "Wi-Fi" between the hosts of scripts/multihost_netns.sh. It runs in a
/// switch network namespace whose interfaces (--ports) lead to one host each (veth pairs), receives
/// every UDP multicast datagram a host sends to the LCM group, and forwards it to every other host
/// through the fault model of transport/netem/link_faults.h (loss, delay with jitter, reordering,
/// duplication; each receiving host drawn independently, as `tc netem` on each port would). It
/// stands in for a Linux bridge plus `tc netem`, which this project's kernel lacks.
///
/// Counted per LCM channel (the datagram's header) and written to --summary at exit (SIGINT /
/// SIGTERM): datagrams received from the hosts, and per forwarded copy delivered, lost, duplicated.
/// A copy's delay counts from the datagram's arrival in the kernel; copies sent past their delivery
/// time because the switch was not scheduled are counted too ("behind", transport/netem/switch_io.h).
#include <arpa/inet.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <queue>
#include <string>
#include <vector>

#include "common/cli.h"
#include "transport/netem/link_faults.h"
#include "transport/netem/switch_io.h"
#include "transport/replay/clock.h"
#include "transport/stop_signal.h"

namespace {

using namespace meshnav;

struct Port {
  std::string name;
  int ifindex = 0;
  int fd = -1;
};

struct Pending {
  int64_t due_us = 0;
  uint64_t order = 0;  ///< FIFO among equal due times
  size_t port = 0;
  std::shared_ptr<std::vector<uint8_t>> data;
  bool operator>(const Pending& o) const { return due_us != o.due_us ? due_us > o.due_us : order > o.order; }
};

struct ChannelCount {
  int64_t received = 0, delivered = 0, lost = 0, duplicated = 0;
};

int openPort(Port& p, const std::string& group, int udp_port) {
  p.ifindex = static_cast<int>(if_nametoindex(p.name.c_str()));
  if (p.ifindex == 0) throw std::runtime_error("no interface " + p.name);
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) throw std::runtime_error("socket: " + std::string(strerror(errno)));
  const int one = 1, zero = 0, ttl = 1;
  setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (setsockopt(fd, SOL_SOCKET, SO_BINDTODEVICE, p.name.c_str(), static_cast<socklen_t>(p.name.size())) != 0)
    throw std::runtime_error("SO_BINDTODEVICE " + p.name + ": " + strerror(errno));
  int rcvbuf = 4 << 20;
  setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
  // The kernel's arrival time of each datagram: one that waited in the socket while the switch was
  // not scheduled is delayed from when it arrived, not from when it was read.
  netem::enableReceiveStamps(fd);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(udp_port));
  addr.sin_addr.s_addr = htonl(INADDR_ANY);
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0)
    throw std::runtime_error("bind " + p.name + ": " + strerror(errno));
  ip_mreqn mreq{};
  inet_pton(AF_INET, group.c_str(), &mreq.imr_multiaddr);
  mreq.imr_ifindex = p.ifindex;
  if (setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) != 0)
    throw std::runtime_error("join " + group + " on " + p.name + ": " + strerror(errno));
  ip_mreqn out{};
  out.imr_ifindex = p.ifindex;
  setsockopt(fd, IPPROTO_IP, IP_MULTICAST_IF, &out, sizeof out);
  setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl);
  setsockopt(fd, IPPROTO_IP, IP_MULTICAST_LOOP, &zero, sizeof zero);
  p.fd = fd;
  return fd;
}

/// The interfaces of a comma-separated list ("veth0,veth1").
std::vector<Port> parsePorts(const std::string& list) {
  std::vector<Port> ports;
  size_t start = 0;
  while (start <= list.size()) {
    size_t end = list.find(',', start);
    if (end == std::string::npos) end = list.size();
    if (end > start) ports.push_back({list.substr(start, end - start)});
    start = end + 1;
  }
  return ports;
}

/// The switch: every datagram received on a port goes to every other port through that port's
/// link emulator, queued until its delivery time.
class Switch {
 public:
  /// Opens the ports (throws naming the interface when one cannot be opened).
  Switch(std::vector<Port> ports, const netem::LinkFaults& faults, uint64_t seed, const std::string& group, int udp_port)
      : ports_(std::move(ports)), faults_(faults) {
    for (size_t i = 0; i < ports_.size(); ++i) {
      fds_.push_back({openPort(ports_[i], group, udp_port), POLLIN, 0});
      links_.emplace_back(faults, seed * 1000003 + i);
    }
    dest_.sin_family = AF_INET;
    dest_.sin_port = htons(static_cast<uint16_t>(udp_port));
    inet_pton(AF_INET, group.c_str(), &dest_.sin_addr);
  }
  ~Switch() {
    for (auto& p : ports_) close(p.fd);
  }
  Switch(const Switch&) = delete;
  Switch& operator=(const Switch&) = delete;

  size_t size() const { return ports_.size(); }

  /// Forwards until SIGINT/SIGTERM. Returns 0, or 1 after a poll error.
  int run() {
    while (!transport::StopSignal::requested()) {
      const int64_t now = replay::wallUtimeNow();
      sendDue(now);
      int timeout_ms = 100;
      if (!queue_.empty())
        timeout_ms = static_cast<int>(std::clamp<int64_t>((queue_.top().due_us - now + 999) / 1000, 0, 100));
      const int n = poll(fds_.data(), fds_.size(), timeout_ms);
      if (n < 0 && errno != EINTR) {
        std::cerr << "meshnav_netem_switch: poll: " << strerror(errno) << "\n";
        return 1;
      }
      if (n <= 0) continue;
      const int64_t received_at = replay::wallUtimeNow();
      for (size_t i = 0; i < fds_.size(); ++i)
        if (fds_[i].revents & POLLIN) receiveFrom(i, received_at);
    }
    return 0;
  }

  /// The counters per channel as YAML (--summary).
  std::string summary() const {
    std::ostringstream out;
    out << "# meshnav_netem_switch: datagrams per LCM channel. received = sent by a host; lost, duplicated,\n"
           "# delivered count the copies towards the other "
        << ports_.size() - 1 << " hosts each.\nfaults: \"" << faults_.toString() << "\"\nports: " << ports_.size()
        << "\n# copies the switch sent more than " << netem::SwitchLag::kLateUs / 1000
        << " ms after their delivery time (it was not scheduled: a loaded machine, not --netem)\n"
        << "behind: {copies: " << lag_.sent << ", late: " << lag_.late
        << ", max_ms: " << lag_.max_us / 1000 << "}\nchannels:\n";
    for (const auto& [ch, c] : counts_)
      out << "  " << ch << ": {received: " << c.received << ", lost: " << c.lost << ", duplicated: " << c.duplicated
          << ", delivered: " << c.delivered << "}\n";
    for (const auto& [k, v] : port_errors_) out << "# " << k << ": " << v << "\n";
    return out.str();
  }

 private:
  /// Sends every queued copy whose delivery time has come.
  void sendDue(int64_t now) {
    while (!queue_.empty() && queue_.top().due_us <= now) {
      const Pending& p = queue_.top();
      lag_.add(now - p.due_us);
      if (sendto(ports_[p.port].fd, p.data->data(), p.data->size(), 0, reinterpret_cast<sockaddr*>(&dest_),
                 sizeof dest_) < 0)
        ++port_errors_[ports_[p.port].name + ":send_error"];
      queue_.pop();
    }
  }
  /// Reads every waiting datagram of port `i` and queues its copies towards the other ports.
  void receiveFrom(size_t i, int64_t now) {
    while (true) {
      int64_t arrived = now;
      const ssize_t got = netem::receiveStamped(fds_[i].fd, buf_, now, arrived);
      if (got < 0) break;
      std::string ch = netem::lcmChannelOf(buf_.data(), static_cast<size_t>(got));
      if (ch.empty()) ch = "(fragments)";
      ChannelCount& c = counts_[ch];
      ++c.received;
      auto data = std::make_shared<std::vector<uint8_t>>(buf_.begin(), buf_.begin() + got);
      for (size_t j = 0; j < ports_.size(); ++j) {
        if (j == i) continue;
        const auto d = links_[j].deliveries();
        if (d.empty()) ++c.lost;
        if (d.size() > 1) ++c.duplicated;
        for (int64_t delay : d) {
          ++c.delivered;
          queue_.push({arrived + delay, order_++, j, data});
        }
      }
    }
  }

  std::vector<Port> ports_;
  netem::LinkFaults faults_;
  std::vector<netem::LinkEmulator> links_;  ///< towards each port
  std::vector<pollfd> fds_;
  std::priority_queue<Pending, std::vector<Pending>, std::greater<>> queue_;
  std::map<std::string, ChannelCount> counts_;
  std::map<std::string, int64_t> port_errors_;
  netem::SwitchLag lag_;
  uint64_t order_ = 0;
  std::vector<uint8_t> buf_ = std::vector<uint8_t>(70000);
  sockaddr_in dest_{};
};

}  // namespace

int main(int argc, char** argv) {
  Cli cli("meshnav_netem_switch",
          "Forwards LCM's UDP multicast between the hosts of scripts/multihost_netns.sh (one interface per host) "
          "through a netem-like fault model (loss, delay with jitter, reordering, duplication), counted per LCM "
          "channel. Stops on SIGINT/SIGTERM and writes --summary.");
  std::string ports_list, netem_spec, group = "239.255.76.67", summary;
  int udp_port = 7667;
  uint64_t seed = 1;
  cli.optional("ports", ports_list, "interfaces of this namespace, one per host")->type_name("IF[,IF...]")->required();
  cli.option("netem", netem_spec, "faults of every link in tc netem's words: \"loss 20% delay 20ms 10ms duplicate 1% reorder 5%\"")
      ->type_name("SPEC");
  cli.option("group", group, "LCM multicast group")->type_name("ADDR");
  cli.option("port", udp_port, "LCM UDP port")->type_name("N");
  cli.option("seed", seed, "random seed of the faults")->type_name("N");
  cli.optional("summary", summary, "write the counters per channel (YAML) here at exit")->type_name("FILE");
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  netem::LinkFaults faults;
  try {
    faults = netem::LinkFaults::parse(netem_spec);
  } catch (const std::exception& e) {
    std::cerr << "meshnav_netem_switch: --netem: " << e.what() << "\n";
    return 2;
  }
  transport::StopSignal::install();
  std::unique_ptr<Switch> sw;
  try {
    sw = std::make_unique<Switch>(parsePorts(ports_list), faults, seed, group, udp_port);
  } catch (const std::exception& e) {
    std::cerr << "meshnav_netem_switch: " << e.what() << "\n";
    return 1;
  }
  std::cout << "meshnav_netem_switch: " << sw->size() << " ports, group " << group << ":" << udp_port
            << ", faults: " << (faults.none() ? "none" : faults.toString()) << std::endl;
  if (const int rc = sw->run(); rc != 0) return rc;
  const std::string text = sw->summary();
  std::cout << text << std::flush;
  if (!summary.empty()) std::ofstream(summary) << text;
  return 0;
}
