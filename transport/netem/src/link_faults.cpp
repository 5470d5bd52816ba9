#include "transport/netem/link_faults.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace meshnav::netem {

namespace {

/// The number at the start of `v` (NaN when there is none) and where it ends.
double leadingNumber(const std::string& v, size_t& n) {
  n = 0;
  try {
    return std::stod(v, &n);
  } catch (const std::exception&) {
    return std::nan("");
  }
}

double percent(const std::string& word, const std::string& v) {
  size_t n = 0;
  const double x = leadingNumber(v, n);
  const bool pct = n + 1 == v.size() && v.back() == '%';
  if (!(pct || n == v.size()) || !std::isfinite(x) || x < 0 || x > 100)
    throw std::invalid_argument("netem: " + word + " needs a percentage 0-100%, got '" + v + "'");
  return x / 100.0;
}

int64_t duration(const std::string& word, const std::string& v) {
  size_t n = 0;
  const double x = leadingNumber(v, n);
  const std::string unit = v.substr(n);
  const double scale = unit == "us" ? 1.0 : unit == "ms" ? 1e3 : unit == "s" ? 1e6 : -1.0;
  if (scale < 0 || !std::isfinite(x) || x < 0 || x * scale > 60e6)
    throw std::invalid_argument("netem: " + word + " needs a time 0-60 s with unit us, ms or s, got '" + v + "'");
  return std::llround(x * scale);
}

bool isTime(const std::string& v) {
  return !v.empty() && (std::isdigit(static_cast<unsigned char>(v[0])) || v[0] == '.') &&
         (v.ends_with("us") || v.ends_with("ms") || v.ends_with("s"));
}

}  // namespace

LinkFaults LinkFaults::parse(const std::string& spec) {
  std::istringstream in(spec);
  std::vector<std::string> w;
  for (std::string s; in >> s;) w.push_back(s);
  LinkFaults f;
  for (size_t i = 0; i < w.size(); ++i) {
    const std::string& key = w[i];
    if (i + 1 >= w.size()) throw std::invalid_argument("netem: '" + key + "' needs a value");
    if (key == "loss") {
      f.loss = percent(key, w[++i]);
    } else if (key == "duplicate") {
      f.duplicate = percent(key, w[++i]);
    } else if (key == "reorder") {
      f.reorder = percent(key, w[++i]);
    } else if (key == "delay") {
      f.delay_us = duration(key, w[++i]);
      if (i + 1 < w.size() && isTime(w[i + 1])) f.jitter_us = duration("delay jitter", w[++i]);
    } else {
      throw std::invalid_argument("netem: unknown word '" + key + "' (known: loss, delay, duplicate, reorder)");
    }
  }
  if (f.reorder > 0 && f.delay_us == 0)
    throw std::invalid_argument("netem: reorder needs a delay (as in tc netem)");
  return f;
}

std::string LinkFaults::toString() const {
  std::ostringstream s;
  s << "loss " << loss * 100 << "% delay " << delay_us / 1e3 << "ms " << jitter_us / 1e3 << "ms duplicate "
    << duplicate * 100 << "% reorder " << reorder * 100 << "%";
  return s.str();
}

int64_t LinkEmulator::delay() {
  if (faults_.reorder > 0 && u_(rng_) < faults_.reorder) return 0;
  const double d = static_cast<double>(faults_.delay_us) + (2.0 * u_(rng_) - 1.0) * static_cast<double>(faults_.jitter_us);
  return std::max<int64_t>(0, std::llround(d));
}

std::vector<int64_t> LinkEmulator::deliveries() {
  std::vector<int64_t> out;
  if (faults_.loss > 0 && u_(rng_) < faults_.loss) return out;
  out.push_back(delay());
  if (faults_.duplicate > 0 && u_(rng_) < faults_.duplicate) out.push_back(delay());
  return out;
}

std::string lcmChannelOf(const uint8_t* data, size_t size) {
  auto be32 = [&](size_t at) {
    return (uint32_t{data[at]} << 24) | (uint32_t{data[at + 1]} << 16) | (uint32_t{data[at + 2]} << 8) | data[at + 3];
  };
  auto cstring = [&](size_t at) -> std::string {
    for (size_t i = at; i < size && i < at + 256; ++i)
      if (data[i] == 0) return std::string(reinterpret_cast<const char*>(data + at), i - at);
    return "?";
  };
  if (size >= 8 && be32(0) == 0x4c433032) return cstring(8);  // "LC02": magic, seqno, channel
  if (size >= 20 && be32(0) == 0x4c433033) {                 // "LC03": magic, seqno, size, offset, no, count
    const uint16_t fragment_no = static_cast<uint16_t>((data[16] << 8) | data[17]);
    return fragment_no == 0 ? cstring(20) : std::string();
  }
  return "?";
}

}  // namespace meshnav::netem
