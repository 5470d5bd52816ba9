#pragma once
/// @file scratch_file.h
/// @brief A file in a private temporary folder that a fuzz target rewrites with every input, for
/// parsers that read a path (dataset CSVs, setup.yaml). The folder is per process (libFuzzer's
/// -jobs and CTest's -j run targets side by side) and removed on destruction.

#include <cstddef>
#include <cstdint>
#include <string>

namespace meshnav::fuzz {

class ScratchFile {
 public:
  /// `name` is the file's base name ("ranges.csv"): readers use it in their counter keys.
  explicit ScratchFile(const std::string& name);
  ~ScratchFile();
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;

  /// Replaces the file's content with `size` bytes; returns its path.
  const std::string& write(const uint8_t* data, size_t size);
  const std::string& path() const { return path_; }
  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
  std::string path_;
};

}  // namespace meshnav::fuzz
