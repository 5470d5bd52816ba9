// Cutting what a killed (-9) logger left half written (logging/torn_tail.h): a torn CSV row, a torn
// LCM event at any byte, and the log read back by LCM's own reader after a restart appended to it.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "logging/torn_tail.h"
#include "tests/support/test_util.h"
#include "transport/input_journal.h"

using namespace meshnav::logging;
namespace fs = std::filesystem;

namespace {

fs::path freshFile(const std::string& name) {
  static const meshnav::test::TempDir d("torn");  // removed at exit
  const fs::path f = d / name;
  fs::remove(f);
  return f;
}

void writeBytes(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}

std::string readBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// One event in the layout of LCM's event log (magic, number, time stamp, lengths big-endian).
std::string lcmEvent(int64_t number, int64_t utime, const std::string& channel, const std::string& data) {
  std::string e;
  auto put = [&e](uint64_t v, int bytes) {
    for (int i = bytes - 1; i >= 0; --i) e.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  };
  put(0xEDA1DA01u, 4);
  put(static_cast<uint64_t>(number), 8);
  put(static_cast<uint64_t>(utime), 8);
  put(channel.size(), 4);
  put(data.size(), 4);
  return e + channel + data;
}

/// Events as LCM's reader sees them: channel and data of each.
std::vector<std::pair<std::string, std::string>> readWithLcm(const fs::path& p) {
  std::vector<std::pair<std::string, std::string>> out;
  meshnav::transport::InputJournal::read(p.string(), [&](const std::string& ch, const lcm::ReceiveBuffer& rbuf) {
    out.emplace_back(ch, std::string(static_cast<const char*>(rbuf.data), rbuf.data_size));
  });
  return out;
}

}  // namespace

TEST(TornTail, ATornCsvRowIsCut) {
  const auto f = freshFile("rows.csv");
  EXPECT_EQ(cutTornLine(f.string()), 0);  // absent
  writeBytes(f, "t,x\n1,2\n3,4");
  EXPECT_EQ(cutTornLine(f.string()), 3);
  EXPECT_EQ(readBytes(f), "t,x\n1,2\n");
  EXPECT_EQ(cutTornLine(f.string()), 0);  // whole rows: untouched
  EXPECT_EQ(readBytes(f), "t,x\n1,2\n");
  writeBytes(f, "");
  EXPECT_EQ(cutTornLine(f.string()), 0);
  writeBytes(f, "no newline at all");
  EXPECT_EQ(cutTornLine(f.string()), 17);
  EXPECT_EQ(readBytes(f), "");
  // A torn row longer than the block the file is read back in.
  const std::string head = "t,x\n" + std::string(5000, '1') + "\n";
  writeBytes(f, head + std::string(9000, '2'));
  EXPECT_EQ(cutTornLine(f.string()), 9000);
  EXPECT_EQ(readBytes(f), head);
}

TEST(TornTail, ALcmLogIsCutBackToItsLastWholeEventWhereverItWasTorn) {
  const auto f = freshFile("events.lcmlog");
  EXPECT_EQ(cutTornLcmLogEvent(f.string()), 0);  // absent
  const std::string e1 = lcmEvent(0, 1000, "POSE", std::string(37, 'a'));
  const std::string e2 = lcmEvent(1, 2000, "ANCHORS", "");
  const std::string e3 = lcmEvent(2, 3000, "ANCHOR_INIT", std::string(60, 'c'));
  const std::string all = e1 + e2 + e3;
  for (size_t n = 0; n <= all.size(); ++n) {
    writeBytes(f, all.substr(0, n));
    const size_t whole = n < e1.size()               ? 0
                         : n < e1.size() + e2.size() ? e1.size()
                         : n < all.size()            ? e1.size() + e2.size()
                                                     : all.size();
    ASSERT_EQ(cutTornLcmLogEvent(f.string()), static_cast<int64_t>(n - whole)) << "torn after " << n << " bytes";
    ASSERT_EQ(readBytes(f), all.substr(0, whole)) << "torn after " << n << " bytes";
  }
  // Bytes that are not an event after the last whole one (a bad magic, a channel length beyond
  // LCM's limit) are cut too: LCM's reader stops there.
  writeBytes(f, e1 + std::string(40, 'x'));
  EXPECT_EQ(cutTornLcmLogEvent(f.string()), 40);
  std::string long_channel = lcmEvent(1, 2000, std::string(300, 'C'), "d");
  writeBytes(f, e1 + long_channel);
  EXPECT_EQ(cutTornLcmLogEvent(f.string()), static_cast<int64_t>(long_channel.size()));
  EXPECT_EQ(readBytes(f), e1);
}

TEST(TornTail, EventsAppendedAfterACutTornEventAreReadBackByLcm) {
  // What the respawned logger does with its --lcmlog: written with LCM, torn by a kill -9 in the
  // middle of the third event, cut, continued with LCM ("a"), read back with LCM's reader.
  const auto f = freshFile("continued.lcmlog");
  auto write = [&](const char* mode, int64_t first, int n) {
    lcm::LogFile log(f.string(), mode);
    ASSERT_TRUE(log.good());
    for (int64_t i = first; i < first + n; ++i) {
      std::string data(100, static_cast<char>('a' + i));
      lcm::LogEvent ev{i, 1000 * i, "POSE", static_cast<int32_t>(data.size()), data.data()};
      ASSERT_EQ(log.writeEvent(&ev), 0);
    }
  };
  write("w", 0, 3);
  const auto size = fs::file_size(f);
  fs::resize_file(f, size - 50);  // the kill: the last event half written
  {
    // Without the cut, LCM's reader stops at the torn event: what is appended after it is lost.
    const auto torn_copy = freshFile("torn_copy.lcmlog");
    fs::copy_file(f, torn_copy);
    {
      lcm::LogFile log(torn_copy.string(), "a");
      std::string data(100, 'z');
      lcm::LogEvent ev{0, 9000, "POSE", static_cast<int32_t>(data.size()), data.data()};
      ASSERT_EQ(log.writeEvent(&ev), 0);
    }
    EXPECT_EQ(readWithLcm(torn_copy).size(), 2u);
  }
  EXPECT_EQ(cutTornLcmLogEvent(f.string()), static_cast<int64_t>(size - 50 - 2 * (28 + 4 + 100)));
  write("a", 3, 2);
  const auto events = readWithLcm(f);
  ASSERT_EQ(events.size(), 4u);
  EXPECT_EQ(events[1].second, std::string(100, 'b'));
  EXPECT_EQ(events[2].second, std::string(100, 'd'));
  EXPECT_EQ(events[3].second, std::string(100, 'e'));
}
