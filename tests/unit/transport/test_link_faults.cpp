// The link fault model of the multi-host tests (transport/netem/link_faults.h): netem's words,
// the drawn loss, duplication, delay and reordering, and the channel of an LCM datagram; the
// switch's receive stamps and its own lag (switch_io.h).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <thread>

#include "transport/netem/link_faults.h"
#include "transport/netem/switch_io.h"

using namespace meshnav::netem;

TEST(LinkFaults, ParsesNetemWords) {
  const auto f = LinkFaults::parse("loss 20% delay 20ms 10ms duplicate 1% reorder 5%");
  EXPECT_DOUBLE_EQ(f.loss, 0.2);
  EXPECT_DOUBLE_EQ(f.duplicate, 0.01);
  EXPECT_DOUBLE_EQ(f.reorder, 0.05);
  EXPECT_EQ(f.delay_us, 20000);
  EXPECT_EQ(f.jitter_us, 10000);
  EXPECT_TRUE(LinkFaults::parse("").none());
  EXPECT_EQ(LinkFaults::parse("delay 1.5s").delay_us, 1500000);
  EXPECT_EQ(LinkFaults::parse("delay 300us loss 5%").jitter_us, 0);
}

TEST(LinkFaults, RefusesWhatNetemWouldNot) {
  for (const char* bad : {"loss", "loss 120%", "loss -1%", "loss x", "delay 20", "delay 20 parsecs",
                          "delay 2h", "jitter 5ms", "reorder 5%", "loss 5%%", "delay nanms"}) {
    EXPECT_THROW(LinkFaults::parse(bad), std::invalid_argument) << bad;
  }
  try {
    LinkFaults::parse("corrupt 1%");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("corrupt"), std::string::npos);
  }
}

TEST(LinkFaults, DrawsLossDuplicationAndDelayAsSpecified) {
  LinkEmulator link(LinkFaults::parse("loss 20% delay 20ms 10ms duplicate 5%"), 7);
  const int n = 100000;
  int lost = 0, dup = 0;
  int64_t min_d = INT64_MAX, max_d = 0;
  double sum = 0;
  int delivered = 0;
  for (int i = 0; i < n; ++i) {
    const auto d = link.deliveries();
    if (d.empty()) ++lost;
    if (d.size() == 2) ++dup;
    for (int64_t x : d) {
      min_d = std::min(min_d, x);
      max_d = std::max(max_d, x);
      sum += static_cast<double>(x);
      ++delivered;
    }
  }
  EXPECT_NEAR(lost / double(n), 0.20, 0.01);
  EXPECT_NEAR(dup / double(n - lost), 0.05, 0.005);
  EXPECT_GE(min_d, 10000);
  EXPECT_LE(max_d, 30000);
  EXPECT_NEAR(sum / delivered, 20000, 200);
}

TEST(LinkFaults, ReorderSendsSomeAtOnce) {
  LinkEmulator link(LinkFaults::parse("delay 20ms reorder 25%"), 3);
  int immediate = 0;
  for (int i = 0; i < 10000; ++i) {
    const auto d = link.deliveries();
    ASSERT_EQ(d.size(), 1u);
    if (d[0] == 0) ++immediate;
    else EXPECT_EQ(d[0], 20000);
  }
  EXPECT_NEAR(immediate / 10000.0, 0.25, 0.02);
}

TEST(LinkFaults, ChannelOfLcmDatagrams) {
  std::vector<uint8_t> shortmsg = {'L', 'C', '0', '2', 0, 0, 0, 7};
  for (char c : std::string("RANGE")) shortmsg.push_back(static_cast<uint8_t>(c));
  shortmsg.push_back(0);
  shortmsg.push_back(42);
  EXPECT_EQ(lcmChannelOf(shortmsg.data(), shortmsg.size()), "RANGE");
  std::vector<uint8_t> frag0(20, 0);
  std::memcpy(frag0.data(), "LC03", 4);
  for (char c : std::string("ANCHORS")) frag0.push_back(static_cast<uint8_t>(c));
  frag0.push_back(0);
  EXPECT_EQ(lcmChannelOf(frag0.data(), frag0.size()), "ANCHORS");
  frag0[17] = 1;  // fragment 1: no channel in it
  EXPECT_EQ(lcmChannelOf(frag0.data(), frag0.size()), "");
  const uint8_t junk[] = {1, 2, 3};
  EXPECT_EQ(lcmChannelOf(junk, sizeof junk), "?");
  shortmsg.resize(10);  // channel without its terminating NUL
  EXPECT_EQ(lcmChannelOf(shortmsg.data(), shortmsg.size()), "?");
}

// The switch's own lag (transport/netem/switch_io.h): copies sent past their delivery time.
TEST(SwitchLag, CountsCopiesSentPastTheirTime) {
  SwitchLag lag;
  lag.add(-5);                          // early: the queue's top was not due yet (not sent)
  lag.add(0);                           // on time
  lag.add(SwitchLag::kLateUs);          // at the limit: not late
  lag.add(SwitchLag::kLateUs + 1);      // late
  lag.add(9'500'000);                   // the CI run's switch, 9.5 s behind
  EXPECT_EQ(lag.sent, 5);
  EXPECT_EQ(lag.late, 2);
  EXPECT_EQ(lag.max_us, 9'500'000);
}

// A datagram's delay counts from its arrival in the kernel: one read 80 ms after it arrived (the
// switch was not scheduled) carries its arrival time, not the read time. On a loaded machine the
// loopback delivery itself can be deferred until about the read (seen once in a CI run with both
// cores busy: arrival stamped 0.02 ms before the read), so up to five tries; a stamp that is the
// read time fails every one.
TEST(SwitchLag, ReceiveTimeIsTheKernelsArrivalTime) {
  const int rx = socket(AF_INET, SOCK_DGRAM, 0), tx = socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(rx, 0);
  ASSERT_GE(tx, 0);
  ASSERT_TRUE(enableReceiveStamps(rx));
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(rx, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  socklen_t len = sizeof addr;
  ASSERT_EQ(getsockname(rx, reinterpret_cast<sockaddr*>(&addr), &len), 0);
  std::vector<uint8_t> buf(100);
  int64_t arrived = 0;
  EXPECT_LT(receiveStamped(rx, buf, 0, arrived), 0);  // nothing waiting: no wait either
  const auto wall = [] {
    return std::chrono::duration_cast<std::chrono::microseconds>(
               std::chrono::system_clock::now().time_since_epoch()).count();
  };
  bool stamped_at_arrival = false;
  for (int attempt = 0; attempt < 5 && !stamped_at_arrival; ++attempt) {
    const int64_t sent = wall();
    ASSERT_EQ(sendto(tx, "LC02", 4, 0, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 4);
    std::this_thread::sleep_for(std::chrono::milliseconds(80));
    const int64_t read_at = wall();
    ASSERT_EQ(receiveStamped(rx, buf, read_at, arrived), 4);
    EXPECT_EQ(std::memcmp(buf.data(), "LC02", 4), 0);
    EXPECT_GE(arrived, sent - 1000);  // the system clock's and the kernel stamp's rounding
    EXPECT_LE(arrived, read_at + 1000);
    stamped_at_arrival = arrived <= read_at - 70'000;  // 80 ms before the read, less scheduling slack
  }
  EXPECT_TRUE(stamped_at_arrival) << "the receive stamp followed the read, not the arrival, in 5 tries";
  close(rx);
  close(tx);
}
