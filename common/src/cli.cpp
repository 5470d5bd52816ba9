#include "common/cli.h"

#include <spdlog/spdlog.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iostream>

namespace meshnav {

Cli::Cli(std::string program, std::string usage) : program_(std::move(program)), usage_(std::move(usage)) {
  declared_["help"] = false;
}

Cli& Cli::option(const std::string& name, bool takes_value) {
  declared_[name] = takes_value;
  return *this;
}

bool Cli::parse(int argc, char** argv, int& exit_code) {
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      std::cout << usage_ << std::endl;
      exit_code = 0;
      return false;
    }
    if (a.rfind("--", 0) != 0 || a == "--") {
      positional_.push_back(a);
      continue;
    }
    std::string name = a.substr(2);
    std::string value;
    bool inline_value = false;
    if (auto eq = name.find('='); eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      inline_value = true;
    }
    auto it = declared_.find(name);
    if (it == declared_.end()) {
      std::cerr << program_ << ": unknown option --" << name << "\n\n" << usage_ << std::endl;
      exit_code = 2;
      return false;
    }
    if (it->second && !inline_value) {
      if (i + 1 >= argc) {
        std::cerr << program_ << ": option --" << name << " needs a value\n\n" << usage_ << std::endl;
        exit_code = 2;
        return false;
      }
      value = argv[++i];
    }
    values_[name] = it->second ? value : "1";
  }
  exit_code = 0;
  return true;
}

bool Cli::has(const std::string& name) const { return values_.count(name) > 0; }

std::string Cli::get(const std::string& name, const std::string& fallback) const {
  auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

double Cli::getDouble(const std::string& name, double fallback) const {
  auto it = values_.find(name);
  if (it == values_.end()) return fallback;
  char* end = nullptr;
  double v = std::strtod(it->second.c_str(), &end);
  if (end == it->second.c_str() || *end != '\0' || !std::isfinite(v)) {
    throw std::runtime_error(program_ + ": option --" + name + " expects a finite number, got '" + it->second + "'");
  }
  return v;
}

int64_t Cli::getInt(const std::string& name, int64_t fallback) const {
  auto it = values_.find(name);
  if (it == values_.end()) return fallback;
  char* end = nullptr;
  errno = 0;
  long long v = std::strtoll(it->second.c_str(), &end, 10);
  if (end == it->second.c_str() || *end != '\0' || errno == ERANGE) {
    throw std::runtime_error(program_ + ": option --" + name + " expects an integer, got '" + it->second + "'");
  }
  return v;
}

void setupLogging(const std::string& program) {
  spdlog::set_pattern("[%H:%M:%S.%e] [" + program + "] [%^%l%$] %v");
  const char* lvl = std::getenv("MESHNAV_LOG_LEVEL");
  if (lvl) spdlog::set_level(spdlog::level::from_str(lvl));
}

}  // namespace meshnav
