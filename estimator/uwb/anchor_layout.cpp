#include "estimator/uwb/anchor_layout.h"

#include <spdlog/fmt/fmt.h>

#include <vector>

#include "common/principal_axes.h"

namespace meshnav::estimator {

std::optional<AnchorLayout> AnchorLayout::of(const std::map<SensorId, Eigen::Vector3d>& anchors_inG) {
  if (anchors_inG.size() < 2) return std::nullopt;
  std::vector<Eigen::Vector3d> plan;
  AnchorLayout l;
  for (const auto& [id, p] : anchors_inG) {
    if (!p.allFinite()) return std::nullopt;
    plan.emplace_back(p.x(), p.y(), 0.0);
    l.centroid_G_ += p;
  }
  l.n_ = static_cast<int>(plan.size());
  l.centroid_G_ /= l.n_;
  const PrincipalAxes axes = principalAxes(plan);
  l.spread_m_ = axes.rms_m.head<2>();
  // The largest axis of points in z = 0 is horizontal; the second is not when they lie exactly on
  // a line (then every axis normal to it has no spread, z among them): across is z × line.
  Eigen::Vector3d line = axes.axes.col(0);
  line.z() = 0.0;
  if (line.norm() > 1e-9) l.line_G_ = line.normalized();
  l.across_G_ = Eigen::Vector3d::UnitZ().cross(l.line_G_);
  return l;
}

std::string AnchorLayout::describe() const {
  std::string text = fmt::format("{} known anchors: horizontal RMS spread {:.2f} / {:.2f} m, line ratio {:.2f}", n_,
                                 spread_m_(0), spread_m_(1), lineRatio());
  if (spread_m_(0) < kOnePointM)
    return text + ": they stand at one horizontal position, so ranges cannot fix the horizontal "
                  "direction to the vehicle. Place anchors apart.";
  if (nearlyCollinear())
    text += fmt::format(
        " < {:.2f}: their horizontal positions are nearly on one line (direction [{:.2f}, {:.2f}] through [{:.2f}, "
        "{:.2f}] m). A position and its mirror image across the vertical plane through that line give the same "
        "ranges; near that plane the position across it is weakly fixed and errors of a metre are possible. Place an "
        "anchor off the line (or, if the line is a wall, state flight_volume in setup.yaml).",
        kCollinearRatio, line_G_.x(), line_G_.y(), centroid_G_.x(), centroid_G_.y());
  return text;
}

}  // namespace meshnav::estimator
