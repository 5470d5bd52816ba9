#include "uwb_bridge/line_reader.h"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace meshnav::uwb {
namespace {

speed_t baudConstant(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 921600: return B921600;
    default: throw std::invalid_argument("unsupported baud rate " + std::to_string(baud));
  }
}

}  // namespace

LineReader::LineReader(const std::string& path, int baud) : path_(path) {
  if (path == "-") {
    fd_ = STDIN_FILENO;
  } else {
    fd_ = ::open(path.c_str(), O_RDONLY | O_NOCTTY | O_CLOEXEC);
    if (fd_ < 0) throw std::runtime_error(path + ": cannot open: " + std::strerror(errno));
    owns_fd_ = true;
  }
  if (::isatty(fd_)) {
    termios tio{};
    if (::tcgetattr(fd_, &tio) != 0) throw std::runtime_error(path + ": tcgetattr: " + std::strerror(errno));
    ::cfmakeraw(&tio);
    tio.c_cflag |= CLOCAL | CREAD;
    if (baud > 0) {
      ::cfsetispeed(&tio, baudConstant(baud));
      ::cfsetospeed(&tio, baudConstant(baud));
    }
    tio.c_cc[VMIN] = 1;
    tio.c_cc[VTIME] = 0;
    if (::tcsetattr(fd_, TCSANOW, &tio) != 0) throw std::runtime_error(path + ": tcsetattr: " + std::strerror(errno));
  }
}

LineReader::~LineReader() {
  if (owns_fd_ && fd_ >= 0) ::close(fd_);
}

bool LineReader::takeLine(std::string& line) {
  const auto nl = buf_.find('\n');
  if (nl != std::string::npos) {
    line = buf_.substr(0, nl);
    buf_.erase(0, nl + 1);
    return true;
  }
  if (buf_.size() >= kMaxLine) {
    line = buf_.substr(0, kMaxLine);
    buf_.erase(0, kMaxLine);
    return true;
  }
  return false;
}

LineReader::Status LineReader::readLine(std::string& line, int timeout_ms) {
  if (takeLine(line)) return Status::Line;
  if (eof_) {
    if (!buf_.empty()) {
      line.swap(buf_);
      buf_.clear();
      return Status::Line;
    }
    return Status::Eof;
  }
  pollfd pfd{fd_, POLLIN, 0};
  const int rc = ::poll(&pfd, 1, timeout_ms);
  if (rc == 0) return Status::Timeout;
  if (rc < 0) return errno == EINTR ? Status::Timeout : Status::Error;
  char chunk[1024];
  const ssize_t n = ::read(fd_, chunk, sizeof(chunk));
  if (n < 0) return (errno == EINTR || errno == EAGAIN) ? Status::Timeout : Status::Error;
  if (n == 0) {
    eof_ = true;
    return readLine(line, 0);
  }
  buf_.append(chunk, static_cast<size_t>(n));
  if (takeLine(line)) return Status::Line;
  return Status::Timeout;
}

}  // namespace meshnav::uwb
