/// @file atomic_file.cpp
/// @brief writeFileAtomically (common/atomic_file.h).
#include "common/atomic_file.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace meshnav {

void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  if (target.has_parent_path()) fs::create_directories(target.parent_path());
  const fs::path tmp = path + ".tmp";
  auto fail = [&](int err, const std::string& what) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw std::runtime_error(path + ": " + what + " (" + (err ? std::string(std::strerror(err)) : "stream error") +
                             "; nothing written)");
  };
  errno = 0;
  std::ofstream out(tmp, std::ios::trunc);
  if (!out) fail(errno, "cannot write");
  errno = 0;
  write(out);
  if (!out) fail(errno, "write failed");  // a write that overflowed the buffer failed already
  errno = 0;
  out.flush();
  if (!out) fail(errno, "write failed");
  out.close();
  if (!out) fail(errno, "write failed");
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) fail(ec.value(), "cannot rename " + tmp.filename().string() + " over it");
}

}  // namespace meshnav
