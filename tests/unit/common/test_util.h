#pragma once
// Helpers for common tests: a fresh temp folder and a file writer.
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace meshnav::test {

inline std::filesystem::path tempDir(const std::string& name) {
  static std::mt19937_64 rng(std::random_device{}());
  auto d = std::filesystem::temp_directory_path() / ("meshnav_" + name + "_" + std::to_string(rng()));
  std::filesystem::create_directories(d);
  return d;
}

inline std::string writeFile(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p) << text;
  return p.string();
}

}  // namespace meshnav::test
