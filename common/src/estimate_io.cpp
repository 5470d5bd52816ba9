#include "common/estimate_io.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <utility>

#include "common/csv.h"
#include "common/dataset.h"

namespace meshnav {

namespace {

std::ofstream openOut(const std::string& path, const char* header, bool append) {
  std::filesystem::path p(path);
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
  std::error_code ec;
  const bool continues = append && std::filesystem::file_size(p, ec) > 0 && !ec;
  std::ofstream out(path, continues ? std::ios::app : std::ios::trunc);
  if (!out) throw std::runtime_error(path + ": cannot write file");
  if (!continues) out << header;
  return out;
}

const char* kEstimateHeader = "t,tx,ty,tz,qx,qy,qz,qw,pxx,pxy,pxz,pyy,pyz,pzz,qrr,qrp,qry,qpp,qpy,qyy\n";
const char* kAnchorsHeader = "t,id,x,y,z,pxx,pxy,pxz,pyy,pyz,pzz\n";

/// Appends ",<v>" as printf's "%.<precision>g" writes v (std::to_chars with a precision is
/// specified so; it formats exactly, without snprintf's format parsing and multi-precision path,
/// which were 9 % of a `meshnav run`).
char* appendG(char* p, char* end, double v, int precision) {
  *p++ = ',';
  return std::to_chars(p, end, v, std::chars_format::general, precision).ptr;
}

/// Appends the 6 upper-triangle values of `m` with 6 significant digits.
char* appendUpper(char* p, char* end, const Eigen::Matrix3d& m) {
  for (const auto& [r, c] : {std::pair{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}}) p = appendG(p, end, m(r, c), 6);
  return p;
}

/// Reads the 6 upper-triangle values `names` into a symmetric matrix.
std::optional<Eigen::Matrix3d> upper(const CsvRow& r, const char* const names[6]) {
  double v[6];
  for (int i = 0; i < 6; ++i) {
    auto x = r.number(names[i]);
    if (!x) return std::nullopt;
    v[i] = *x;
  }
  Eigen::Matrix3d m;
  m << v[0], v[1], v[2], v[1], v[3], v[4], v[2], v[4], v[5];
  return m;
}

}  // namespace

std::string StreamTally::lost() const {
  const int64_t n = rows - kept_rows;
  const std::string after = kept_until_t.empty() ? "from its first row" : "after t = " + kept_until_t + " s";
  return "the file is incomplete: " + std::to_string(n) + " rows " + after + " (" + std::to_string(bytes - kept_bytes) +
         " bytes), written since the last flush that succeeded, are lost or torn";
}

void checkedFlush(std::ofstream& out, const std::string& path, int first_errno, StreamTally* tally) {
  errno = 0;
  out.flush();
  if (out) {
    if (tally) tally->flushed();
    return;
  }
  const int err = first_errno ? first_errno : errno;
  throw std::runtime_error(path + ": write failed (" + (err ? std::string(std::strerror(err)) : "stream error") +
                           "; " + (tally ? tally->lost() : std::string("the file is incomplete")) + ")");
}

EstimateCsvWriter::EstimateCsvWriter(const std::string& path, bool append)
    : path_(path), out_(openOut(path, kEstimateHeader, append)) {}

void EstimateCsvWriter::write(const PoseEstimate& e) {
  // t,tx,ty,tz,qx,qy,qz,qw with 9 significant digits, the covariances' upper triangles with 6.
  const std::string t = formatSeconds(e.t);
  char buf[512];
  char* const end = buf + sizeof(buf);
  char* p = std::copy(t.begin(), t.end(), buf);
  for (const double v : {e.p_IinG.x(), e.p_IinG.y(), e.p_IinG.z(), e.q_ItoG.x(), e.q_ItoG.y(), e.q_ItoG.z(),
                         e.q_ItoG.w()})
    p = appendG(p, end, v, 9);
  p = appendUpper(p, end, e.cov_p_m2);
  p = appendUpper(p, end, e.cov_theta_rad2);
  *p++ = '\n';
  errno = 0;
  out_.write(buf, p - buf);
  if (!out_ && errno_ == 0) errno_ = errno;
  tally_.wrote(t, static_cast<size_t>(p - buf));
}

void EstimateCsvWriter::flush() { checkedFlush(out_, path_, errno_, &tally_); }

AnchorsCsvWriter::AnchorsCsvWriter(const std::string& path, bool append)
    : path_(path), out_(openOut(path, kAnchorsHeader, append)) {}

void AnchorsCsvWriter::write(const AnchorEstimate& a) {
  // t,id,x,y,z with 9 significant digits, the covariance's upper triangle with 6.
  const std::string t = formatSeconds(a.t);
  char buf[384];
  char* const end = buf + sizeof(buf);
  char* p = std::copy(t.begin(), t.end(), buf);
  *p++ = ',';
  p = std::to_chars(p, end, a.id).ptr;
  for (const double v : {a.p_AinG.x(), a.p_AinG.y(), a.p_AinG.z()}) p = appendG(p, end, v, 9);
  p = appendUpper(p, end, a.cov_p_m2);
  *p++ = '\n';
  errno = 0;
  out_.write(buf, p - buf);
  if (!out_ && errno_ == 0) errno_ = errno;
  tally_.wrote(t, static_cast<size_t>(p - buf));
}

void AnchorsCsvWriter::flush() { checkedFlush(out_, path_, errno_, &tally_); }

std::vector<PoseEstimate> readEstimateCsv(const std::string& path, Diagnostics& diag) {
  static const char* const kP[6] = {"pxx", "pxy", "pxz", "pyy", "pyz", "pzz"};
  static const char* const kQ[6] = {"qrr", "qrp", "qry", "qpp", "qpy", "qyy"};
  const auto sample = [&](const CsvRow& r, Timestamp t, const std::string& key) -> std::optional<PoseEstimate> {
    auto tx = r.number("tx"), ty = r.number("ty"), tz = r.number("tz");
    auto qx = r.number("qx"), qy = r.number("qy"), qz = r.number("qz"), qw = r.number("qw");
    auto P = upper(r, kP);
    auto Q = upper(r, kQ);
    if (!tx || !ty || !tz || !qx || !qy || !qz || !qw || !P || !Q) {
      diag.report(key + ":bad_value", r.where() + ": a value is missing or not finite; row skipped");
      return std::nullopt;
    }
    PoseEstimate e;
    e.t = t;
    e.p_IinG = {*tx, *ty, *tz};
    const Eigen::Quaterniond q(*qw, *qx, *qy, *qz);
    if (std::abs(q.norm() - 1.0) > 0.1) {  // as groundtruth.csv: a zero quaternion stays zero
      diag.report(key + ":bad_quaternion", r.where() + ": quaternion norm " + std::to_string(q.norm()) +
                                               " is far from 1; row skipped");
      return std::nullopt;
    }
    e.q_ItoG = q.normalized();
    e.cov_p_m2 = *P;
    e.cov_theta_rad2 = *Q;
    return e;
  };
  return readTimedRows<PoseEstimate>(path,
                                     {"t", "tx", "ty", "tz", "qx", "qy", "qz", "qw", "pxx", "pxy", "pxz", "pyy",
                                      "pyz", "pzz", "qrr", "qrp", "qry", "qpp", "qpy", "qyy"},
                                     diag, sample);
}

std::vector<AnchorEstimate> readAnchorsCsv(const std::string& path, Diagnostics& diag) {
  static const char* const kP[6] = {"pxx", "pxy", "pxz", "pyy", "pyz", "pzz"};
  const auto sample = [&](const CsvRow& r, Timestamp t, const std::string& key) -> std::optional<AnchorEstimate> {
    auto id = r.number("id"), x = r.number("x"), y = r.number("y"), z = r.number("z");
    auto P = upper(r, kP);
    if (!id || !x || !y || !z || !P) {
      diag.report(key + ":bad_value", r.where() + ": a value is missing or not finite; row skipped");
      return std::nullopt;
    }
    // a cast of anything but a whole number in [0, INT32_MAX] to SensorId is undefined
    if (*id != std::floor(*id) || *id < 0 || *id > INT32_MAX) {
      diag.report(key + ":bad_id", r.where() + ": id '" + r.text("id") + "' is not a device id; row skipped");
      return std::nullopt;
    }
    return AnchorEstimate{t, static_cast<SensorId>(*id), {*x, *y, *z}, *P};
  };
  return readTimedRows<AnchorEstimate>(path, {"t", "id", "x", "y", "z", "pxx", "pxy", "pxz", "pyy", "pyz", "pzz"},
                                       diag, sample);
}

std::vector<PoseSample> readPosesAuto(const std::string& path, Diagnostics& diag) {
  CsvReader probe(path, {});
  bool is_estimate = false;
  for (const auto& c : probe.header()) is_estimate |= (c == "pxx");
  if (!is_estimate) return readTumCsv(path, diag);
  std::vector<PoseSample> out;
  for (const auto& e : readEstimateCsv(path, diag)) out.push_back({e.t, e.p_IinG, e.q_ItoG});
  return out;
}

}  // namespace meshnav
