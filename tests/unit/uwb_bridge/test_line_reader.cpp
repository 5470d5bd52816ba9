// Reading lines with a timeout from files and pipes (as from a serial device).
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "uwb_bridge/line_reader.h"
#include "tests/support/test_util.h"

using meshnav::uwb::LineReader;
namespace fs = std::filesystem;

TEST(LineReader, FileWithUnterminatedLastLine) {
  const meshnav::test::TempDir dir("lr");
  const fs::path p = dir / "lines.txt";
  std::ofstream(p) << "1 0 1 4.5\r\n2 0 2 5.0\n\n3 0 3 6.0";
  LineReader r(p.string());
  std::vector<std::string> lines;
  std::string line;
  for (int i = 0; i < 100; ++i) {
    const auto st = r.readLine(line, 100);
    if (st == LineReader::Status::Eof) break;
    ASSERT_NE(st, LineReader::Status::Error);
    if (st == LineReader::Status::Line) lines.push_back(line);
  }
  EXPECT_EQ(lines, (std::vector<std::string>{"1 0 1 4.5\r", "2 0 2 5.0", "", "3 0 3 6.0"}));
  fs::remove(p);
}

TEST(LineReader, PipeDeliversPartialWritesAsWholeLines) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  LineReader r("/dev/fd/" + std::to_string(fds[0]));
  std::string line;
  EXPECT_EQ(r.readLine(line, 0), LineReader::Status::Timeout);  // nothing yet
  ASSERT_EQ(::write(fds[1], "12 0 ", 5), 5);
  EXPECT_EQ(r.readLine(line, 100), LineReader::Status::Timeout);  // half a line
  ASSERT_EQ(::write(fds[1], "1 4.25\n13", 9), 9);
  ASSERT_EQ(r.readLine(line, 1000), LineReader::Status::Line);
  EXPECT_EQ(line, "12 0 1 4.25");
  ::close(fds[1]);
  ASSERT_EQ(r.readLine(line, 1000), LineReader::Status::Line);  // the rest at end of input
  EXPECT_EQ(line, "13");
  EXPECT_EQ(r.readLine(line, 1000), LineReader::Status::Eof);
  ::close(fds[0]);
}

TEST(LineReader, OverlongLineIsCut) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  LineReader r("/dev/fd/" + std::to_string(fds[0]));
  const std::string junk(LineReader::kMaxLine + 10, 'x');
  ASSERT_EQ(::write(fds[1], junk.data(), junk.size()), static_cast<ssize_t>(junk.size()));
  ::close(fds[1]);
  std::string line;
  std::vector<size_t> sizes;
  for (int i = 0; i < 100; ++i) {
    const auto st = r.readLine(line, 1000);
    if (st == LineReader::Status::Eof) break;
    if (st == LineReader::Status::Line) sizes.push_back(line.size());
  }
  EXPECT_EQ(sizes, (std::vector<size_t>{LineReader::kMaxLine, 10}));
  ::close(fds[0]);
}

TEST(LineReader, MissingDeviceThrows) { EXPECT_THROW(LineReader("/dev/nonexistent_tty"), std::runtime_error); }
