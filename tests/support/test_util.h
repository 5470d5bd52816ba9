#pragma once
/// @file test_util.h
/// Helpers for the C++ tests: a private temp folder that is removed again, and a file writer.
/// Every test that writes files writes them into a TempDir (docs/contributing.md, "Tests and temp files").
#include <stdlib.h>  // mkdtemp

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <system_error>

namespace meshnav::test {

/// A fresh folder `meshnav_<name>_XXXXXX` under the temp folder ($TMPDIR, else /tmp; CTest points TMPDIR
/// at build/test-tmp/run-*), created by mkdtemp, so its name is unique across parallel ctest jobs and
/// earlier runs. Removed with everything in it when the object goes out of scope, unless the environment
/// variable MESHNAV_KEEP_TEST_FILES=1: then it is kept and its path printed to stderr.
/// A helper that hands out paths for the whole test binary keeps a function-local `static TempDir`:
/// it is removed at normal program exit.
class TempDir {
 public:
  explicit TempDir(const std::string& name = "test") {
    std::string pattern = (std::filesystem::temp_directory_path() / ("meshnav_" + name + "_XXXXXX")).string();
    if (::mkdtemp(pattern.data()) == nullptr)
      throw std::runtime_error("TempDir: cannot create " + pattern + ": " + std::strerror(errno));
    path_ = pattern;
  }
  ~TempDir() {
    if (keep()) {
      std::cerr << "MESHNAV_KEEP_TEST_FILES=1: kept " << path_.string() << "\n";
      return;
    }
    std::error_code ec;  // never throw from a destructor; a failure shows up as a leftover in CTest's check
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  operator const std::filesystem::path&() const { return path_; }  // NOLINT: used wherever a path is
  std::filesystem::path operator/(const std::filesystem::path& p) const { return path_ / p; }
  std::string string() const { return path_.string(); }

  /// True when MESHNAV_KEEP_TEST_FILES=1: temp folders are kept to look at.
  static bool keep() {
    const char* v = std::getenv("MESHNAV_KEEP_TEST_FILES");
    return v != nullptr && std::string(v) == "1";
  }

 private:
  std::filesystem::path path_;
};

inline std::string writeFile(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p) << text;
  return p.string();
}

}  // namespace meshnav::test
