#include "calibrator/reference_geometry.h"

#include "common/principal_axes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <tuple>

namespace meshnav::calib {

namespace {
std::string fmt(const char* f, double a, double b) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b);
  return buf;
}
/// Largest distance from the plane (c, n) of a stationary reference (the mean of its positions).
double stationaryOffset(const CalibrationProblem& pb, const Eigen::Vector3d& c, const Eigen::Vector3d& n) {
  double best = 0.0;
  for (const auto& s : pb.slots())
    if (!s.moving && !s.obs.empty()) best = std::max(best, std::abs((s.p_mean_RinG - c).dot(n)));
  return best;
}
}  // namespace

GeometryReport checkReferenceGeometry(const CalibrationProblem& pb, const CalibratorOptions& options) {
  GeometryReport r;
  r.n_used = pb.numUsed();
  const int n_all = static_cast<int>(pb.observations().size());
  if (r.n_used < options.min_measurements) {
    r.status = CalibrationStatus::TooFewMeasurements;
    r.reason = std::to_string(r.n_used) + " usable ranges (" + std::to_string(n_all) + " collected), need at least " +
               std::to_string(options.min_measurements);
    return r;
  }
  if (pb.numMovingSlots() == 0) {
    r.status = CalibrationStatus::DegenerateGeometry;
    r.reason = "no moving reference (tag): stationary references only fix their own bias, the position is unobservable";
    return r;
  }
  // Distinct positions of the moving references on a grid; their principal spreads.
  std::set<std::tuple<long, long, long>> cells;
  std::vector<Eigen::Vector3d> pts;
  const double res = options.distinct_position_resolution_m;
  for (const auto& s : pb.slots()) {
    if (!s.moving) continue;
    for (int i : s.obs) {
      const auto& p = pb.observations()[static_cast<size_t>(i)].p_RinG;
      if (cells.emplace(std::lround(p.x() / res), std::lround(p.y() / res), std::lround(p.z() / res)).second)
        pts.push_back(p);
    }
  }
  r.distinct_positions = static_cast<int>(pts.size());
  if (r.distinct_positions < options.min_distinct_positions) {
    r.status = CalibrationStatus::TooFewReferencePositions;
    r.reason = std::to_string(r.distinct_positions) + " distinct moving-reference positions" +
               fmt(" (grid %.2f m), need at least %.0f", res, options.min_distinct_positions);
    return r;
  }
  const PrincipalAxes axes = principalAxes(pts);
  r.rms_spread_m = axes.rms_m;
  if (r.rms_spread_m(1) < options.min_line_spread_m) {
    r.status = CalibrationStatus::DegenerateGeometry;
    r.reason = fmt("reference positions are collinear (RMS off their line %.3f m < %.3f m)", r.rms_spread_m(1),
                   options.min_line_spread_m);
    return r;
  }
  if (r.rms_spread_m(2) < options.min_plane_spread_m) {
    // A stationary reference off the plane can tell the anchor's side of it (calibrate() fits both).
    const double off = stationaryOffset(pb, axes.centroid, axes.axes.col(2));
    if (options.mirror_reference_min_offset_m > 0.0 && off >= options.mirror_reference_min_offset_m &&
        r.rms_spread_m(2) < options.mirror_max_plane_spread_m) {
      r.mirror = MirrorPlane{axes.centroid, axes.axes.col(2), off};
      return r;
    }
    r.status = CalibrationStatus::DegenerateGeometry;
    r.reason = fmt("reference positions are coplanar (RMS off their plane %.3f m < %.3f m)", r.rms_spread_m(2),
                   options.min_plane_spread_m) +
               fmt(" and no stationary reference is %.2f m off it (largest %.2f m)",
                   options.mirror_reference_min_offset_m, off);
    return r;
  }
  return r;
}

}  // namespace meshnav::calib
