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

/// Streaming writer of estimate.csv (header written on open). A write that fails (a full disk,
/// a removed folder) is never silent: the stream's failure is sticky, and `flush` throws
/// std::runtime_error "<path>: write failed (...)" from then on, so a run whose file is incomplete
/// cannot end looking healthy.
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
};

/// Flushes `out` and throws std::runtime_error "<path>: write failed (<reason>)" when it failed;
/// `first_errno`: the errno seen when an earlier write failed (0: not known).
void checkedFlush(std::ofstream& out, const std::string& path, int first_errno = 0);

std::vector<PoseEstimate> readEstimateCsv(const std::string& path, Diagnostics& diag);
std::vector<AnchorEstimate> readAnchorsCsv(const std::string& path, Diagnostics& diag);

/// Reads poses either from estimate.csv (detected by its header) or from a TUM file.
std::vector<PoseSample> readPosesAuto(const std::string& path, Diagnostics& diag);

}  // namespace meshnav
