#include "uwb_bridge/range_csv_import.h"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace meshnav::uwb {

std::vector<RangeSample> importRangeCsv(const std::vector<std::string>& paths, Diagnostics& diag,
                                        const RangeLimits& limits) {
  std::vector<RangeSample> all;
  for (const auto& p : paths) {
    auto v = readRangesCsv(p, diag, limits);
    spdlog::debug("{}: {} ranges", p, v.size());
    all.insert(all.end(), v.begin(), v.end());
  }
  std::stable_sort(all.begin(), all.end(), [](const RangeSample& a, const RangeSample& b) { return a.t < b.t; });
  return all;
}

size_t keepInitiators(std::vector<RangeSample>& ranges, const std::set<SensorId>& initiators) {
  if (initiators.empty()) return 0;
  const size_t before = ranges.size();
  std::erase_if(ranges, [&](const RangeSample& r) { return !initiators.count(r.id_initiator); });
  return before - ranges.size();
}

std::vector<std::string> splitPathList(const std::string& list) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= list.size()) {
    size_t end = list.find(',', start);
    if (end == std::string::npos) end = list.size();
    std::string item = list.substr(start, end - start);
    const auto a = item.find_first_not_of(" \t");
    const auto b = item.find_last_not_of(" \t");
    if (a != std::string::npos) out.push_back(item.substr(a, b - a + 1));
    start = end + 1;
  }
  return out;
}

}  // namespace meshnav::uwb
