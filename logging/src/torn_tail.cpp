#include "logging/torn_tail.h"

#include <array>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace meshnav::logging {
namespace fs = std::filesystem;

namespace {

constexpr uint32_t kLcmLogMagic = 0xEDA1DA01u;
constexpr int kLcmLogHeaderBytes = 4 + 8 + 8 + 4 + 4;  // magic, event number, time stamp, channel, data
constexpr int32_t kLcmMaxChannelLength = 255;

uint32_t bigEndian32(const unsigned char* b) {
  return (uint32_t{b[0]} << 24) | (uint32_t{b[1]} << 16) | (uint32_t{b[2]} << 8) | uint32_t{b[3]};
}

/// Cuts `path` to `keep` bytes of its `size`; returns the bytes cut.
int64_t cutTo(const std::string& path, uintmax_t size, uintmax_t keep) {
  if (keep >= size) return 0;
  std::error_code ec;
  fs::resize_file(path, keep, ec);
  if (ec) throw std::runtime_error(path + ": cannot cut the torn end: " + ec.message());
  return static_cast<int64_t>(size - keep);
}

/// Size of `path` (0 when it does not exist).
uintmax_t sizeOf(const std::string& path) {
  std::error_code ec;
  const uintmax_t size = fs::file_size(path, ec);
  return ec ? 0 : size;
}

std::ifstream openToRead(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot read");
  return in;
}

}  // namespace

int64_t cutTornLine(const std::string& path) {
  const uintmax_t size = sizeOf(path);
  if (size == 0) return 0;
  std::ifstream in = openToRead(path);
  // Back from the end in blocks to the last newline.
  std::array<char, 4096> block{};
  uintmax_t end = size;
  while (end > 0) {
    const uintmax_t begin = end > block.size() ? end - block.size() : 0;
    in.seekg(static_cast<std::streamoff>(begin));
    in.read(block.data(), static_cast<std::streamsize>(end - begin));
    if (!in) throw std::runtime_error(path + ": cannot read");
    for (uintmax_t i = end - begin; i-- > 0;)
      if (block[i] == '\n') return cutTo(path, size, begin + i + 1);
    end = begin;
  }
  return cutTo(path, size, 0);  // not one whole line
}

int64_t cutTornLcmLogEvent(const std::string& path) {
  const uintmax_t size = sizeOf(path);
  if (size == 0) return 0;
  std::ifstream in = openToRead(path);
  uintmax_t whole = 0;  // end of the last whole event
  std::array<unsigned char, kLcmLogHeaderBytes> h{};
  while (size - whole >= static_cast<uintmax_t>(kLcmLogHeaderBytes)) {
    in.seekg(static_cast<std::streamoff>(whole));
    in.read(reinterpret_cast<char*>(h.data()), kLcmLogHeaderBytes);
    if (!in) throw std::runtime_error(path + ": cannot read");
    if (bigEndian32(h.data()) != kLcmLogMagic) break;
    const auto channel_len = static_cast<int32_t>(bigEndian32(h.data() + 20));
    const auto data_len = static_cast<int32_t>(bigEndian32(h.data() + 24));
    if (channel_len <= 0 || channel_len > kLcmMaxChannelLength || data_len < 0) break;
    const uintmax_t end = whole + kLcmLogHeaderBytes + static_cast<uintmax_t>(channel_len) +
                          static_cast<uintmax_t>(data_len);
    if (end > size) break;
    whole = end;
  }
  return cutTo(path, size, whole);
}

}  // namespace meshnav::logging
