#include "common/dataset.h"

#include "common/atomic_file.h"
#include "common/plausibility.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "common/csv.h"

namespace meshnav {

namespace fs = std::filesystem;

namespace {

/// Sorts samples by time (stable; logged once per file); readTimedRows has reported each row whose
/// time went backwards.
template <typename T>
void checkOrder(std::vector<T>& v, const std::string& path) {
  if (std::is_sorted(v.begin(), v.end(), [](const T& a, const T& b) { return a.t < b.t; })) return;
  std::stable_sort(v.begin(), v.end(), [](const T& a, const T& b) { return a.t < b.t; });
  spdlog::warn("{}: rows out of time order; the {} rows were sorted by time", path, v.size());
}

std::optional<UwbType> parseType(const std::string& s) {
  if (s == "T" || s == "84" || s == "t") return UwbType::Tag;
  if (s == "A" || s == "65" || s == "a") return UwbType::Anchor;
  return std::nullopt;
}

std::optional<int64_t> parseId(const std::string& s) {
  if (s.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || *end != '\0' || !std::isfinite(v) || v != std::floor(v) || v < 0 || v > 2e9) {
    return std::nullopt;
  }
  return static_cast<int64_t>(v);
}

constexpr size_t kCsvLineMax = 256;  ///< longest line a writer formats (an IMU row is about 110)

/// Writes `header`, then for every sample the line `row(sample, buf)` formats into `buf`.
template <typename T, typename Row>
void writeCsv(const std::vector<T>& v, const std::string& path, const char* header, Row&& row) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << header;
    char buf[kCsvLineMax];
    for (const auto& s : v) {
      row(s, buf);
      out << buf;
    }
  });
}

/// Files `t,<column>` of one number per row; values outside [lo, hi] (or not finite) are reported
/// as "<file>:bad_value" and dropped. T is a {Timestamp, double} sample.
template <typename T>
std::vector<T> readTimeValueCsv(const std::string& path, const char* column, double lo, double hi,
                                const char* expected, Diagnostics& diag) {
  const auto sample = [&](const CsvRow& r, Timestamp t, const std::string& key) -> std::optional<T> {
    auto v = r.number(column);
    if (!v || *v < lo || *v > hi) {
      diag.report(key + ":bad_value", r.where() + ": " + column + " '" + r.text(column) + "' is not " + expected +
                                          "; row skipped");
      return std::nullopt;
    }
    return T{t, *v};
  };
  std::vector<T> out = readTimedRows<T>(path, {"t", column}, diag, sample);
  checkOrder(out, path);
  return out;
}

}  // namespace

std::vector<ImuSample> readImuCsv(const std::string& path, Diagnostics& diag) {
  const std::vector<std::string> cols = {"t", "lin_acc_x", "lin_acc_y", "lin_acc_z", "ang_vel_x", "ang_vel_y", "ang_vel_z"};
  const auto sample = [&](const CsvRow& r, Timestamp t, const std::string& key) -> std::optional<ImuSample> {
    double v[6];
    for (int i = 0; i < 6; ++i) {
      auto x = r.number(cols[i + 1]);
      if (!x) {
        diag.report(key + ":bad_value", r.where() + ": " + cols[i + 1] + " '" + r.text(cols[i + 1]) +
                                            "' is not a finite number; row skipped");
        return std::nullopt;
      }
      v[i] = *x;
    }
    ImuSample s{t, {v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
    if (s.acc_m_s2.norm() > plausible::kMaxSpecificForce_m_s2 || s.gyro_rad_s.norm() > plausible::kMaxAngularRate_rad_s) {
      diag.report(key + ":absurd_value", r.where() + ": IMU reading beyond 500 m/s^2 or 50 rad/s; row skipped");
      return std::nullopt;
    }
    return s;
  };
  std::vector<ImuSample> out = readTimedRows<ImuSample>(path, cols, diag, sample);
  checkOrder(out, path);
  return out;
}

std::vector<BaroSample> readBaroCsv(const std::string& path, Diagnostics& diag) {
  return readTimeValueCsv<BaroSample>(path, "pressure", plausible::kMinPressure_pa, plausible::kMaxPressure_pa,
                                       "a plausible pressure in Pa", diag);
}

std::vector<RangeSample> readRangesCsv(const std::string& path, Diagnostics& diag, const RangeLimits& limits) {
  const auto sample = [&](const CsvRow& r, Timestamp t, const std::string& key) -> std::optional<RangeSample> {
    RangeSample s;
    s.t = t;
    auto id1 = parseId(r.text("UWB_ID1"));
    auto id2 = parseId(r.text("UWB_ID2"));
    if (!id1 || !id2) {
      diag.report(key + ":bad_id", r.where() + ": UWB ids '" + r.text("UWB_ID1") + "', '" + r.text("UWB_ID2") +
                                       "' are not non-negative integers; row skipped");
      return std::nullopt;
    }
    if (*id1 == *id2) {
      diag.report(key + ":self_range", r.where() + ": range from device " + std::to_string(*id1) +
                                           " to itself; row skipped");
      return std::nullopt;
    }
    auto ty1 = parseType(r.text("type_ID1"));
    auto ty2 = parseType(r.text("type_ID2"));
    if (!ty1 || !ty2) {
      diag.report(key + ":bad_type", r.where() + ": device types '" + r.text("type_ID1") + "', '" +
                                         r.text("type_ID2") + "' are not T/A (or 84/65); row skipped");
      return std::nullopt;
    }
    auto z = r.number("range_raw");
    if (!z) {
      diag.report(key + ":nan_range", r.where() + ": range '" + r.text("range_raw") +
                                          "' is not a finite number; row skipped");
      return std::nullopt;
    }
    if (*z < limits.min_m) {
      diag.report(key + ":negative_range", r.where() + ": range " + r.text("range_raw") + " m is below " +
                                               std::to_string(limits.min_m) + " m; row skipped");
      return std::nullopt;
    }
    if (*z > limits.max_m) {
      diag.report(key + ":absurd_range", r.where() + ": range " + r.text("range_raw") + " m exceeds " +
                                             std::to_string(limits.max_m) + " m; row skipped");
      return std::nullopt;
    }
    s.id_initiator = static_cast<SensorId>(*id1);
    s.id_responder = static_cast<SensorId>(*id2);
    s.type_initiator = *ty1;
    s.type_responder = *ty2;
    s.range_m = *z;
    // Optional columns: absent or empty means "not given" (range_corr: the raw range; R: 0, the
    // setup's σ); anything else must be a plausible number, or the row is bad input.
    s.range_corr_m = *z;
    if (r.has("range_corr") && !r.text("range_corr").empty()) {
      const auto zc = r.number("range_corr");
      if (!zc || *zc < limits.min_m || *zc > limits.max_m) {
        diag.report(key + ":bad_range_corr", r.where() + ": range_corr '" + r.text("range_corr") +
                                                 "' is not a number in [" + std::to_string(limits.min_m) + ", " +
                                                 std::to_string(limits.max_m) + "] m; row skipped");
        return std::nullopt;
      }
      s.range_corr_m = *zc;
    }
    s.R_m2 = 0.0;
    if (r.has("R") && !r.text("R").empty()) {
      const auto R = r.number("R");
      if (!R || *R < 0.0 || *R > plausible::kMaxRangeVariance_m2) {
        diag.report(key + ":bad_R", r.where() + ": R '" + r.text("R") + "' is not a variance in [0, " +
                                        std::to_string(plausible::kMaxRangeVariance_m2) + "] m^2; row skipped");
        return std::nullopt;
      }
      s.R_m2 = *R;
    }
    if (r.has("LOS")) {
      const std::string l = r.text("LOS");
      s.los = !(l == "0" || l == "False" || l == "false");
    }
    return s;
  };
  std::vector<RangeSample> out = readTimedRows<RangeSample>(
      path, {"t", "range_raw", "UWB_ID1", "UWB_ID2", "type_ID1", "type_ID2"}, diag, sample);
  checkOrder(out, path);
  return out;
}

std::vector<FlightStateSample> readFlightStateCsv(const std::string& path, Diagnostics& diag) {
  const auto sample = [&](const CsvRow& r, Timestamp t, const std::string& key) -> std::optional<FlightStateSample> {
    const std::string l = r.text("landed");
    bool landed;
    if (l == "1" || l == "true" || l == "True") landed = true;
    else if (l == "0" || l == "false" || l == "False") landed = false;
    else {
      diag.report(key + ":bad_value", r.where() + ": landed '" + l + "' is not 0/1; row skipped");
      return std::nullopt;
    }
    return FlightStateSample{t, landed};
  };
  std::vector<FlightStateSample> out = readTimedRows<FlightStateSample>(path, {"t", "landed"}, diag, sample);
  checkOrder(out, path);
  return out;
}

std::vector<HeightSample> readHeightCsv(const std::string& path, Diagnostics& diag) {
  return readTimeValueCsv<HeightSample>(path, "range_m", 0.0, plausible::kMaxHeight_m, "a height in [0, 100] m", diag);
}

std::vector<PoseSample> readTumCsv(const std::string& path, Diagnostics& diag) {
  const std::vector<std::string> cols = {"t", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
  const auto sample = [&](const CsvRow& r, Timestamp t, const std::string& key) -> std::optional<PoseSample> {
    double v[7];
    for (int i = 0; i < 7; ++i) {
      auto x = r.number(cols[i + 1]);
      if (!x) {
        diag.report(key + ":bad_value", r.where() + ": " + cols[i + 1] + " is not a finite number; row skipped");
        return std::nullopt;
      }
      v[i] = *x;
    }
    Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
    if (std::abs(q.norm() - 1.0) > 0.1) {
      diag.report(key + ":bad_quaternion", r.where() + ": quaternion norm " + std::to_string(q.norm()) +
                                               " is far from 1; row skipped");
      return std::nullopt;
    }
    q.normalize();
    return PoseSample{t, {v[0], v[1], v[2]}, q};
  };
  std::vector<PoseSample> out = readTimedRows<PoseSample>(path, cols, diag, sample);
  checkOrder(out, path);
  return out;
}

void writeImuCsv(const std::vector<ImuSample>& v, const std::string& path) {
  writeCsv(v, path, "t,lin_acc_x,lin_acc_y,lin_acc_z,ang_vel_x,ang_vel_y,ang_vel_z\n", [](const ImuSample& s, char* buf) {
    std::snprintf(buf, kCsvLineMax, "%s,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", formatSeconds(s.t).c_str(), s.acc_m_s2.x(),
                  s.acc_m_s2.y(), s.acc_m_s2.z(), s.gyro_rad_s.x(), s.gyro_rad_s.y(), s.gyro_rad_s.z());
  });
}

void writeBaroCsv(const std::vector<BaroSample>& v, const std::string& path) {
  writeCsv(v, path, "t,pressure\n", [](const BaroSample& s, char* buf) {
    std::snprintf(buf, kCsvLineMax, "%s,%.4f\n", formatSeconds(s.t).c_str(), s.pressure_pa);
  });
}

void writeRangesCsv(const std::vector<RangeSample>& v, const std::string& path) {
  writeCsv(v, path, "t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,type_ID1,type_ID2,LOS\n", [](const RangeSample& s, char* buf) {
    std::snprintf(buf, kCsvLineMax, "%s,%.6f,%.6f,%.6g,%d,%d,%c,%c,%d\n", formatSeconds(s.t).c_str(), s.range_m,
                  s.range_corr_m, s.R_m2, s.id_initiator, s.id_responder, static_cast<char>(s.type_initiator),
                  static_cast<char>(s.type_responder), s.los ? 1 : 0);
  });
}

void writeFlightStateCsv(const std::vector<FlightStateSample>& v, const std::string& path) {
  writeCsv(v, path, "t,landed\n", [](const FlightStateSample& s, char* buf) {
    std::snprintf(buf, kCsvLineMax, "%s,%d\n", formatSeconds(s.t).c_str(), s.landed ? 1 : 0);
  });
}

void writeHeightCsv(const std::vector<HeightSample>& v, const std::string& path) {
  writeCsv(v, path, "t,range_m\n", [](const HeightSample& s, char* buf) {
    std::snprintf(buf, kCsvLineMax, "%s,%.9g\n", formatSeconds(s.t).c_str(), s.range_m);
  });
}

void writeTumCsv(const std::vector<PoseSample>& v, const std::string& path) {
  writeCsv(v, path, "#t,tx,ty,tz,qx,qy,qz,qw\n", [](const PoseSample& s, char* buf) {
    std::snprintf(buf, kCsvLineMax, "%s,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", formatSeconds(s.t).c_str(),
                  s.p_IinG.x(), s.p_IinG.y(), s.p_IinG.z(), s.q_ItoG.x(), s.q_ItoG.y(), s.q_ItoG.z(), s.q_ItoG.w());
  });
}

Dataset readDataset(const std::string& dir, Diagnostics& diag, bool with_truth) {
  if (!fs::is_directory(dir)) throw std::runtime_error(dir + ": dataset folder does not exist");
  Dataset ds;
  const fs::path d(dir);
  ds.setup = loadSetup((d / "setup.yaml").string());
  auto opt = [&](const char* name) { return fs::exists(d / name) ? std::optional<std::string>((d / name).string()) : std::nullopt; };
  if (auto p = opt("imu.csv")) ds.imu = readImuCsv(*p, diag);
  if (auto p = opt("baro.csv")) ds.baro = readBaroCsv(*p, diag);
  if (auto p = opt("ranges.csv")) ds.ranges = readRangesCsv(*p, diag);
  else throw std::runtime_error((d / "ranges.csv").string() + ": missing (a dataset needs ranges)");
  if (auto p = opt("flight_state.csv")) ds.flight_states = readFlightStateCsv(*p, diag);
  if (auto p = opt("height.csv")) ds.heights = readHeightCsv(*p, diag);
  if (auto p = opt("groundtruth.csv")) ds.ground_truth = readTumCsv(*p, diag);
  if (with_truth) {
    if (auto p = opt("truth.yaml")) ds.truth = loadTruth(*p);
    else spdlog::warn("{}: no truth.yaml (evaluation of anchors not possible)", dir);
  }
  return ds;
}

void writeDataset(const Dataset& ds, const std::string& dir) {
  fs::create_directories(dir);
  const fs::path d(dir);
  if (!ds.imu.empty()) writeImuCsv(ds.imu, (d / "imu.csv").string());
  if (!ds.baro.empty()) writeBaroCsv(ds.baro, (d / "baro.csv").string());
  writeRangesCsv(ds.ranges, (d / "ranges.csv").string());
  if (!ds.flight_states.empty()) writeFlightStateCsv(ds.flight_states, (d / "flight_state.csv").string());
  if (!ds.heights.empty()) writeHeightCsv(ds.heights, (d / "height.csv").string());
  if (!ds.ground_truth.empty()) writeTumCsv(ds.ground_truth, (d / "groundtruth.csv").string());
  saveSetup(ds.setup, (d / "setup.yaml").string());
  if (ds.truth) saveTruth(*ds.truth, (d / "truth.yaml").string());
}

}  // namespace meshnav
