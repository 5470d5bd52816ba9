#pragma once
/// @file line_reader.h
/// @brief Reads text lines from a serial device, a FIFO, a file or stdin ("-") with a timeout, so a
/// process loop stays responsive to SIGINT/SIGTERM. A tty is switched to raw 8N1 mode at the given
/// baud rate.

#include <string>

namespace meshnav::uwb {

class LineReader {
 public:
  enum class Status { Line, Timeout, Eof, Error };

  /// Opens `path` ("-" = stdin). `baud` 0 leaves a tty's speed as it is. Throws std::runtime_error
  /// naming the path when it cannot be opened or configured.
  explicit LineReader(const std::string& path, int baud = 0);
  ~LineReader();
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;

  /// Waits up to `timeout_ms` for a complete line (without its '\n'). A line longer than
  /// `kMaxLine` is cut and returned in pieces. At end of input a last unterminated line is
  /// returned before Eof.
  Status readLine(std::string& line, int timeout_ms);

  static constexpr size_t kMaxLine = 4096;

 private:
  bool takeLine(std::string& line);

  std::string path_;
  int fd_ = -1;
  bool owns_fd_ = false;
  bool eof_ = false;
  std::string buf_;
};

}  // namespace meshnav::uwb
