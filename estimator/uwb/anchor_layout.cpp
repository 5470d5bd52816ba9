#include "estimator/uwb/anchor_layout.h"

#include <spdlog/fmt/fmt.h>

#include <Eigen/SVD>
#include <cmath>

namespace meshnav::estimator {

std::optional<AnchorLayout> AnchorLayout::of(const std::map<SensorId, Eigen::Vector3d>& anchors_inG) {
  if (anchors_inG.size() < 2) return std::nullopt;
  AnchorLayout l;
  l.n_ = static_cast<int>(anchors_inG.size());
  for (const auto& [id, p] : anchors_inG) l.centroid_G_ += p / l.n_;
  Eigen::MatrixXd X(l.n_, 3);
  int i = 0;
  for (const auto& [id, p] : anchors_inG) X.row(i++) = (p - l.centroid_G_).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(X, Eigen::ComputeThinV);
  const Eigen::VectorXd s = svd.singularValues();  // descending; min(n, 3) of them
  for (int k = 0; k < s.size() && k < 3; ++k) l.spread_m_(k) = s(k) / std::sqrt(static_cast<double>(l.n_));
  l.line_G_ = svd.matrixV().col(0);
  return l;
}

std::string AnchorLayout::describe() const {
  std::string text = fmt::format(
      "{} known anchors: RMS spread {:.2f} / {:.2f} / {:.2f} m along their principal axes, line ratio {:.2f}", n_,
      spread_m_(0), spread_m_(1), spread_m_(2), lineRatio());
  if (nearlyCollinear())
    text += fmt::format(
        " < {:.2f}: nearly on one line (direction [{:.2f}, {:.2f}, {:.2f}] through [{:.2f}, {:.2f}, {:.2f}] m). A "
        "position and its mirror image across the plane through that line give the same ranges; near that plane "
        "the position across it is weakly fixed and errors of a metre are possible. Place an anchor off the line.",
        kCollinearRatio, line_G_.x(), line_G_.y(), line_G_.z(), centroid_G_.x(), centroid_G_.y(), centroid_G_.z());
  return text;
}

}  // namespace meshnav::estimator
