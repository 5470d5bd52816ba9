#include "common/csv.h"

#include <charconv>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace meshnav {

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

/// Splits on commas when the line has any, otherwise on white space (TUM files).
std::vector<std::string> splitFields(const std::string& line) {
  std::vector<std::string> out;
  if (line.find(',') != std::string::npos) {
    // Every piece between commas, an empty one after a trailing comma too (a stream per line,
    // as before, was most of reading a dataset).
    for (size_t b = 0;;) {
      const size_t e = line.find(',', b);
      out.push_back(trim(line.substr(b, e == std::string::npos ? std::string::npos : e - b)));
      if (e == std::string::npos) break;
      b = e + 1;
    }
  } else {
    std::istringstream is(line);
    std::string field;
    while (is >> field) out.push_back(field);
  }
  return out;
}

}  // namespace

std::string baseName(const std::string& path) {
  const auto p = path.find_last_of('/');
  return p == std::string::npos ? path : path.substr(p + 1);
}

std::optional<Timestamp> parseRowTime(const CsvRow& r, const std::string& key, Diagnostics& d,
                                      const std::string& col) {
  const auto s = r.number(col);
  if (!s) {
    d.report(key + ":bad_time", r.where() + ": time '" + r.text(col) + "' is not a finite number; row skipped");
    return std::nullopt;
  }
  const auto t = Timestamp::tryFromSec(*s);
  if (!t)
    d.report(key + ":bad_time", r.where() + ": time '" + r.text(col) + "' s does not fit a time stamp (|t| <= " +
                                    std::to_string(static_cast<long long>(kMaxTimeSeconds)) + " s); row skipped");
  return t;
}

std::string CsvRow::where() const { return (file_ ? *file_ : std::string("?")) + ":" + std::to_string(line_); }

bool CsvRow::has(const std::string& name) const { return columns_->count(name) > 0; }

std::string CsvRow::text(const std::string& name) const {
  auto it = columns_->find(name);
  if (it == columns_->end() || it->second >= static_cast<int>(fields_.size())) return "";
  return fields_[it->second];
}

std::optional<double> CsvRow::number(const std::string& name) const {
  auto it = columns_->find(name);
  if (it == columns_->end() || it->second >= static_cast<int>(fields_.size())) return std::nullopt;
  const std::string& s = fields_[it->second];  // text(name) without its copy
  if (s.empty()) return std::nullopt;
  // from_chars (no locale, no allocation) reads the plain decimal numbers every file has; what it
  // does not take whole (a leading '+' or space, hex) gets strtod's reading as before. Both round
  // correctly, so a number reads the same either way.
  double v = 0.0;
  const char* const first = s.data();
  const char* const last = first + s.size();
  if (const auto [ptr, ec] = std::from_chars(first, last, v); ec != std::errc() || ptr != last) {
    char* end = nullptr;
    v = std::strtod(s.c_str(), &end);
    if (end == s.c_str() || *end != '\0') return std::nullopt;
  }
  if (!std::isfinite(v)) return std::nullopt;
  return v;
}

uint64_t maxCsvBytes() {
  constexpr uint64_t kDefaultMiB = 64;
  uint64_t mib = kDefaultMiB;
  if (const char* env = std::getenv("MESHNAV_MAX_CSV_MB"); env && *env) {
    char* end = nullptr;
    const unsigned long long v = std::strtoull(env, &end, 10);
    // A value that is not a limit is refused, not ignored (issue 36): the user meant something.
    if (end == env || *end != '\0' || env[0] == '-' || !(v > 0 && v < (1ull << 40)))
      throw std::runtime_error(std::string("MESHNAV_MAX_CSV_MB='") + env +
                               "' is not a limit: a whole number of MiB, 1 or more (unset it for the default " +
                               std::to_string(kDefaultMiB) + ")");
    mib = v;
  }
  return mib << 20;
}

CsvReader::CsvReader(const std::string& path, const std::vector<std::string>& required) : path_(path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open file");
  std::error_code ec;
  const uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (!ec && bytes > maxCsvBytes())
    throw std::runtime_error(path + ": " + std::to_string(bytes >> 20) + " MiB is more than the " +
                             std::to_string(maxCsvBytes() >> 20) +
                             " MiB a dataset file may hold (every sample is kept in memory); split the "
                             "recording, or raise the limit with MESHNAV_MAX_CSV_MB (docs/faults.md)");
  std::string line;
  bool got = false;
  while (std::getline(in, line)) {
    if (!trim(line).empty()) {
      got = true;
      break;
    }
  }
  if (!got) throw std::runtime_error(path + ": empty file (no header line)");
  // A UTF-8 byte order mark (spreadsheet exports write one) is not part of the first column's name.
  if (line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
  std::string h = trim(line);
  if (!h.empty() && h[0] == '#') h = trim(h.substr(1));
  header_ = splitFields(h);
  for (size_t i = 0; i < header_.size(); ++i) columns_[header_[i]] = static_cast<int>(i);
  for (const auto& r : required) {
    if (!columns_.count(r)) {
      std::string have;
      for (const auto& c : header_) have += (have.empty() ? "" : ",") + c;
      throw std::runtime_error(path + ":1: missing column '" + r + "' (header has: " + have + ")");
    }
  }
}

void CsvReader::forEach(const std::function<void(const CsvRow&)>& fn, Diagnostics& diag) {
  std::ifstream in(path_);
  if (!in) throw std::runtime_error(path_ + ": cannot open file");
  std::string line;
  int line_no = 0;
  bool header_seen = false;
  const std::string base = baseName(path_);
  CsvRow row;
  row.file_ = &path_;
  row.columns_ = &columns_;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = trim(line);
    if (t.empty()) continue;
    if (!header_seen) {
      header_seen = true;
      continue;
    }
    if (t[0] == '#') continue;
    row.line_ = line_no;
    row.fields_ = splitFields(t);
    if (row.fields_.size() != header_.size()) {
      diag.report(base + ":bad_row", path_ + ":" + std::to_string(line_no) + ": expected " +
                                         std::to_string(header_.size()) + " fields, got " +
                                         std::to_string(row.fields_.size()) + "; row skipped");
      continue;
    }
    fn(row);
  }
}

}  // namespace meshnav
