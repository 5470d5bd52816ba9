#pragma once
/// @file estimate_io.h
/// @brief Estimate files of a run folder (docs/formats.md).
///  - estimate.csv: t,tx,ty,tz,qx,qy,qz,qw,pxx,pxy,pxz,pyy,pyz,pzz,qrr,qrp,qry,qpp,qpy,qyy
///    (upper triangles; position covariance in G [m²], orientation error covariance local [rad²])
///  - anchors.csv:  t,id,x,y,z,pxx,pxy,pxz,pyy,pyz,pzz

#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/types.h"

namespace meshnav {

/// What a streamed CSV writer handed to its stream and what its last successful flush kept: the
/// message of a failed write says which rows are lost (issue 36: "the bytes lost").
struct StreamTally {
  int64_t rows = 0, bytes = 0;            ///< rows and bytes written (handed to the stream)
  int64_t kept_rows = 0, kept_bytes = 0;  ///< the same at the last successful flush
  std::string last_t, kept_until_t;       ///< time [s] of the last row written / kept ("" before any)
  void wrote(const std::string& t, size_t n) {
    ++rows;
    bytes += static_cast<int64_t>(n);
    last_t = t;
  }
  void flushed() {
    kept_rows = rows;
    kept_bytes = bytes;
    kept_until_t = last_t;
  }
  /// "the file ends with the last successful flush, N rows after t = X s (B bytes) are lost".
  std::string lost() const;
};

/// Streaming writer of estimate.csv (header written on open). A write that fails (a full disk,
/// a removed folder) is never silent: the stream's failure is sticky, and `flush` throws
/// std::runtime_error "<path>: write failed (...)" from then on, so a run whose file is incomplete
/// cannot end looking healthy; the message says how many rows after which time are lost.
class EstimateCsvWriter {
 public:
  /// `append`: continue an existing non-empty file (a restarted logger) instead of starting anew.
  explicit EstimateCsvWriter(const std::string& path, bool append = false);
  void write(const PoseEstimate& e);
  /// Throws std::runtime_error naming the file when a write or the flush failed.
  void flush();

 private:
  std::string path_;
  std::ofstream out_;
  int errno_ = 0;  ///< errno of the first failed write (0: none, or not known)
  StreamTally tally_;
};

/// Streaming writer of anchors.csv (header written on open); failures as EstimateCsvWriter's.
class AnchorsCsvWriter {
 public:
  /// `append`: as EstimateCsvWriter.
  explicit AnchorsCsvWriter(const std::string& path, bool append = false);
  void write(const AnchorEstimate& a);
  /// Throws std::runtime_error naming the file when a write or the flush failed.
  void flush();

 private:
  std::string path_;
  std::ofstream out_;
  int errno_ = 0;  ///< errno of the first failed write (0: none, or not known)
  StreamTally tally_;
};

/// Flushes `out` and throws std::runtime_error "<path>: write failed (<reason>; …)" when it failed;
/// `first_errno`: the errno seen when an earlier write failed (0: not known); `tally`: the rows
/// written, marked kept on success and named in the message on failure.
void checkedFlush(std::ofstream& out, const std::string& path, int first_errno = 0, StreamTally* tally = nullptr);

std::vector<PoseEstimate> readEstimateCsv(const std::string& path, Diagnostics& diag);
std::vector<AnchorEstimate> readAnchorsCsv(const std::string& path, Diagnostics& diag);

/// Reads poses either from estimate.csv (detected by its header) or from a TUM file.
std::vector<PoseSample> readPosesAuto(const std::string& path, Diagnostics& diag);

}  // namespace meshnav
