#include "common/diagnostics.h"

#include <spdlog/spdlog.h>

#include <sstream>

namespace meshnav {

void Diagnostics::report(const std::string& kind, const std::string& message) {
  int64_t n;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    n = ++counts_[kind];
  }
  if (n <= max_logged_per_kind) {
    spdlog::warn("{}", message);
  } else if (n == max_logged_per_kind + 1) {
    spdlog::warn("{} (further '{}' messages are counted, not logged)", message, kind);
  }
}

void Diagnostics::count(const std::string& kind, int64_t n) {
  std::lock_guard<std::mutex> lock(mutex_);
  counts_[kind] += n;
}

int64_t Diagnostics::get(const std::string& kind) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = counts_.find(kind);
  return it == counts_.end() ? 0 : it->second;
}

int64_t Diagnostics::total() const {
  std::lock_guard<std::mutex> lock(mutex_);
  int64_t s = 0;
  for (const auto& [k, v] : counts_) s += v;
  return s;
}

std::map<std::string, int64_t> Diagnostics::snapshot() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counts_;
}

void Diagnostics::merge(const Diagnostics& other) {
  auto snap = other.snapshot();
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [k, v] : snap) counts_[k] += v;
}

std::string Diagnostics::summary() const {
  std::ostringstream os;
  bool first = true;
  for (const auto& [k, v] : snapshot()) {
    os << (first ? "" : ", ") << k << "=" << v;
    first = false;
  }
  return os.str();
}

}  // namespace meshnav
