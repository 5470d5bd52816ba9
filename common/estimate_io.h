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

/// Streaming writer of estimate.csv (header written on open).
class EstimateCsvWriter {
 public:
  /// `append`: continue an existing non-empty file (a restarted logger) instead of starting anew.
  explicit EstimateCsvWriter(const std::string& path, bool append = false);
  void write(const PoseEstimate& e);
  void flush();

 private:
  std::ofstream out_;
};

/// Streaming writer of anchors.csv (header written on open).
class AnchorsCsvWriter {
 public:
  /// `append`: as EstimateCsvWriter.
  explicit AnchorsCsvWriter(const std::string& path, bool append = false);
  void write(const AnchorEstimate& a);
  void flush();

 private:
  std::ofstream out_;
};

std::vector<PoseEstimate> readEstimateCsv(const std::string& path, Diagnostics& diag);
std::vector<AnchorEstimate> readAnchorsCsv(const std::string& path, Diagnostics& diag);

/// Reads poses either from estimate.csv (detected by its header) or from a TUM file.
std::vector<PoseSample> readPosesAuto(const std::string& path, Diagnostics& diag);

}  // namespace meshnav
