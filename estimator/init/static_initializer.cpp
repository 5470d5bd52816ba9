#include "estimator/init/static_initializer.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "common/atmosphere.h"
#include "estimator/core/cauchy.h"
#include "estimator/core/huber.h"

namespace meshnav::estimator {

namespace {
constexpr double kDeg = M_PI / 180.0;

Eigen::Matrix3d rotZ(double yaw) { return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

/// Why the fit is ambiguous ("" when it is not): a second minimum within `chi2` of the best cost
/// elsewhere (nearly coplanar anchors mirror the position) or at another heading (lever arms too
/// short for the range noise). Refused rather than one picked.
std::string ambiguityOf(const std::vector<StaticInitializer::FitMinimum>& minima, const StaticInitializer::FitMinimum& best,
                        double chi2) {
  using FitMinimum = StaticInitializer::FitMinimum;
  for (const FitMinimum& m : minima) {
    if (m.cost - best.cost >= chi2) continue;
    if ((m.p - best.p).norm() > 0.5)
      return "motion: two positions " + std::to_string((m.p - best.p).norm()) +
             " m apart fit the landed ranges alike (known anchors nearly coplanar?)";
    const double dyaw = std::abs(std::remainder(m.yaw - best.yaw, 2.0 * M_PI));
    if (dyaw > 30.0 * kDeg) return "motion: two headings " + std::to_string(dyaw / kDeg) + " deg apart fit the ranges alike";
  }
  return "";
}
}  // namespace

StaticInitializer::StaticInitializer(const EstimatorOptions& options, const SystemSetup& setup)
    : options_(options), setup_(setup), network_(setup, options.uwb.sigma_range_m) {}

bool StaticInitializer::isStatic() const {
  if (landed_) return *landed_;
  return still_ || options_.init.assume_landed_without_flight_state;
}

void StaticInitializer::addStillness(bool still) {
  if (landed_) return;  // a flight state, once received, decides
  const bool was_static = isStatic();
  still_ = still;
  if (was_static && !isStatic()) took_off_ = true;
  if (!was_static && isStatic()) restart();
}

void StaticInitializer::restart() {
  static_since_.reset();
  n_imu_ = 0;
  sum_acc_.setZero();
  sum_gyro_.setZero();
  n_baro_ = 0;
  sum_pressure_ = 0.0;
  ranges_.clear();
  last_fit_t_.reset();
}

void StaticInitializer::addFlightState(const FlightStateSample& s) {
  const bool was_static = isStatic();
  landed_ = s.landed;
  if (was_static && !s.landed) took_off_ = true;
  if (!was_static && s.landed) restart();
}

void StaticInitializer::addImu(const ImuSample& s) {
  if (!isStatic()) return;
  if (!static_since_) static_since_ = s.t;
  last_imu_ = s;
  ++n_imu_;
  sum_acc_ += s.acc_m_s2;
  sum_gyro_ += s.gyro_rad_s;
}

void StaticInitializer::addBaro(const BaroSample& s) {
  if (!isStatic()) return;
  ++n_baro_;
  sum_pressure_ += s.pressure_pa;
}

void StaticInitializer::addRange(const RangeSample& s) {
  if (!isStatic()) return;
  SensorId tag = s.id_initiator, anchor = s.id_responder;
  if (!setup_.isTag(tag)) std::swap(tag, anchor);
  if (!setup_.isTag(tag) || !setup_.isKnownAnchor(anchor)) return;
  const PairBias pb = network_.pairBias(tag, anchor);
  const double z = options_.uwb.use_corrected_range ? s.range_corr_m : s.range_m;
  InitRange r;
  r.tag = tag;
  r.anchor = anchor;
  r.d_m = (z - pb.gamma_m) / pb.beta;
  r.sigma_m = network_.rangeSigma(tag, anchor, s.R_m2);
  ranges_.push_back(r);
  // The newest ones only: a body that rests long (a hover the ranges cannot fix) must not make
  // every retry slower (90 s of ranges took 30 min of fits).
  if (ranges_.size() > kMaxRanges) ranges_.erase(ranges_.begin(), ranges_.begin() + (ranges_.size() - kMaxRanges));
}

std::optional<InitialBelief> StaticInitializer::tryInitialize() {
  if (!last_imu_ || n_imu_ == 0 || !static_since_) {
    waiting_for_ = "landed IMU data";
    return std::nullopt;
  }
  const double collected_s = (last_imu_->t - *static_since_).sec();
  // After take-off initialize with what was collected (if anything useful), else wait.
  const bool enough_time = collected_s >= options_.init.duration_s || (took_off_ && collected_s > 0.1);
  if (!enough_time) {
    waiting_for_ = "landed data (" + std::to_string(collected_s) + " s of " + std::to_string(options_.init.duration_s) + " s)";
    return std::nullopt;
  }
  const Eigen::Vector3d f = sum_acc_ / n_imu_;
  const double roll = std::atan2(f.y(), f.z());
  const double pitch = std::atan2(-f.x(), std::hypot(f.y(), f.z()));
  const Eigen::Matrix3d R_rp = (Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX())).toRotationMatrix();
  auto belief = build(R_rp);
  if (!belief && took_off_) restart();  // flying: the landed data is stale
  return belief;
}

std::optional<InitialBelief> StaticInitializer::build(const Eigen::Matrix3d& R_rp) {
  InitialBelief b;
  b.t = last_imu_->t;
  b.last_imu = *last_imu_;
  b.landed = isStatic();
  Eigen::Vector3d p;
  double yaw = 0.0, sigma_p = 0.0, sigma_yaw = 0.0;
  if (setup_.initial_pose) {
    p = setup_.initial_pose->p_IinG;
    yaw = setup_.initial_pose->yaw_deg * kDeg;
    sigma_p = setup_.initial_pose->sigma_p_m;
    sigma_yaw = setup_.initial_pose->sigma_yaw_deg * kDeg;
  } else {
    if (static_cast<int>(ranges_.size()) < options_.init.min_ranges) {
      waiting_for_ =
          "tag ranges to known anchors (" + std::to_string(ranges_.size()) + " of " +
          std::to_string(options_.init.min_ranges) + ")";
      return std::nullopt;
    }
    // Retried at most every kRetryS of data time (tryInitialize runs at every input).
    if (last_fit_t_ && b.t >= *last_fit_t_ && (b.t - *last_fit_t_).sec() < kRetryS) return std::nullopt;
    last_fit_t_ = b.t;
    Eigen::Matrix4d cov;
    if (!fitPoseToRanges(R_rp, p, yaw, cov, b.range_fit_rms_m, b.n_ranges_used)) {
      if (waiting_for_.empty()) waiting_for_ = "a converging range fit";
      return std::nullopt;
    }
    b.from_ranges = true;
    sigma_p = std::max(options_.init.range_init_min_sigma_p_m, std::sqrt(cov.topLeftCorner<3, 3>().diagonal().maxCoeff()));
    sigma_yaw = std::max(options_.init.range_init_sigma_yaw_deg * kDeg, std::sqrt(cov(3, 3)));
    if (std::sqrt(cov(3, 3)) > options_.init.static_max_sigma_yaw_deg * kDeg) {
      waiting_for_ = "motion: yaw is not observable at rest with this tag geometry (range fit σ_yaw " +
                     std::to_string(std::sqrt(cov(3, 3)) / kDeg) + " deg)";
      return std::nullopt;
    }
  }
  const Eigen::Matrix3d R = rotZ(yaw) * R_rp;
  b.imu.p_IinG = p;
  b.imu.v_IinG.setZero();
  b.imu.q_ItoG = Eigen::Quaterniond(R).normalized();
  b.imu.bias_gyro_rad_s = sum_gyro_ / n_imu_;
  b.imu.bias_acc_m_s2.setZero();

  const Eigen::Vector3d n = R.transpose() * Eigen::Vector3d::UnitZ();
  const double s_rp = options_.init.sigma_roll_pitch_deg * kDeg;
  const Eigen::Matrix3d I3 = Eigen::Matrix3d::Identity();
  b.cov.setZero();
  b.cov.block<3, 3>(ImuErr::kP, ImuErr::kP) = I3 * sigma_p * sigma_p;
  // Rest known only from IMU stillness: the body may drift and turn slowly (ZuptOptions).
  const bool on_stillness = !landed_ && still_;
  const double sigma_v = on_stillness ? std::max(options_.init.sigma_v_m_s, options_.zupt.stillness_sigma_vel_m_s)
                                      : options_.init.sigma_v_m_s;
  const double sigma_bg = on_stillness
                              ? std::max(options_.init.sigma_bias_gyro_rad_s, options_.zupt.stillness_sigma_gyro_rad_s)
                              : options_.init.sigma_bias_gyro_rad_s;
  b.cov.block<3, 3>(ImuErr::kV, ImuErr::kV) = I3 * sigma_v * sigma_v;
  b.cov.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) =
      s_rp * s_rp * (I3 - n * n.transpose()) + sigma_yaw * sigma_yaw * n * n.transpose();
  b.cov.block<3, 3>(ImuErr::kBg, ImuErr::kBg) = I3 * sigma_bg * sigma_bg;
  b.cov.block<3, 3>(ImuErr::kBa, ImuErr::kBa) = I3 * std::pow(options_.init.sigma_bias_acc_m_s2, 2);

  // Barometer: reference and bias.
  const double baro_z = (p + R * setup_.baro_p_IP).z();
  if (setup_.baro_reference_pressure_pa) {
    b.baro_reference_pa = *setup_.baro_reference_pressure_pa;
    b.baro_bias_m = 0.0;
    b.baro_bias_var_m2 = std::pow(options_.baro.init_bias_sigma_m, 2);
  } else if (n_baro_ > 0) {
    const double p_ref = sum_pressure_ / n_baro_;
    const double sigma_h = std::abs(atmosphere::dHeightDPressure(p_ref, p_ref)) * options_.baro.pressure_sigma_pa;
    b.baro_reference_pa = p_ref;
    b.baro_bias_m = -baro_z;  // mean measured height is 0 at the reference
    b.baro_bias_var_m2 = sigma_p * sigma_p + sigma_h * sigma_h / n_baro_ + 0.01;
  }
  return b;
}

double StaticInitializer::solveFit(const Eigen::Matrix3d& R_rp, const std::vector<bool>& use, Eigen::Vector3d& p,
                                   double& yaw, Eigen::Matrix4d* cov, FitLoss loss) const {
  const auto rho = [loss](double e) { return loss == FitLoss::kCauchy ? cauchy::cost(e) : huber::cost(e); };
  const auto weight = [loss](double e) { return loss == FitLoss::kCauchy ? cauchy::weight(e) : huber::weight(e); };
  double cost = 0.0;
  for (int it = 0; it < 30; ++it) {
    Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
    Eigen::Vector4d g = Eigen::Vector4d::Zero();
    cost = 0.0;
    const Eigen::Matrix3d R = rotZ(yaw) * R_rp;
    for (size_t i = 0; i < ranges_.size(); ++i) {
      if (!use[i]) continue;
      const InitRange& r = ranges_[i];
      const Eigen::Vector3d lever = R * setup_.rel_tag_positions.at(r.tag);
      const Eigen::Vector3d delta = setup_.abs_anchor_positions.at(r.anchor) - p - lever;
      const double d = std::max(delta.norm(), 1e-6);
      const Eigen::Vector3d u = delta / d;
      const double res = r.d_m - d;
      Eigen::Vector4d J;  // ∂res/∂[p, yaw]
      J.head<3>() = u;
      J(3) = u.dot(Eigen::Vector3d::UnitZ().cross(lever));
      // Robust (FitLoss): NLOS outliers must not pick the minimum (a 109° yaw error in hover).
      const double e = res / r.sigma_m;
      const double w = weight(e) / (r.sigma_m * r.sigma_m);
      A += w * J * J.transpose();
      g += w * J * res;
      cost += rho(e);
    }
    if (height_prior_) {  // ∂(z_h − p_z)/∂[p, yaw] = −e_z (roll and pitch fixed: the lever's z does not depend on yaw)
      const double res = height_prior_->z_m - p.z();
      const double e = res / height_prior_->sigma_m;
      // Huber under either loss: the prior is not an outlier candidate, and a redescending loss
      // would let a mirror image metres away in height escape it.
      const double w = huber::weight(e) / (height_prior_->sigma_m * height_prior_->sigma_m);
      A(2, 2) += w;
      g(2) -= w * res;
      cost += huber::cost(e);
    }
    A.diagonal().array() += 1e-9;
    A(3, 3) += 1.0 / (M_PI * M_PI);  // weak yaw prior: one tag leaves yaw (nearly) unobservable
    const Eigen::Vector4d step = -A.ldlt().solve(g);
    p += step.head<3>();
    yaw = std::remainder(yaw + step(3), 2.0 * M_PI);
    if (cov) *cov = A.inverse();
    if (step.norm() < 1e-9) break;
  }
  return cost;
}

std::optional<StaticInitializer::HeightPrior> StaticInitializer::heightPrior(const Eigen::Matrix3d& R_rp) const {
  if (setup_.baro_reference_pressure_pa && n_baro_ > 0 && options_.baro.enabled) {
    const double p_mean = sum_pressure_ / n_baro_;
    const double ref = *setup_.baro_reference_pressure_pa;
    const double sigma_h = std::abs(atmosphere::dHeightDPressure(p_mean, ref)) * options_.baro.pressure_sigma_pa;
    return HeightPrior{atmosphere::heightFromPressure(p_mean, ref) - (R_rp * setup_.baro_p_IP).z(),
                       std::sqrt(std::pow(options_.baro.init_bias_sigma_m, 2) + sigma_h * sigma_h / n_baro_)};
  }
  if (setup_.carried_height && options_.carried_height.enabled)
    return HeightPrior{setup_.carried_height->height_m,
                       std::hypot(setup_.carried_height->sigma_m, options_.carried_height.sigma_m)};
  return std::nullopt;
}

std::vector<StaticInitializer::FitMinimum> StaticInitializer::searchMinima(const Eigen::Matrix3d& R_rp,
                                                                          const std::vector<bool>& use,
                                                                          const Eigen::Vector3d& centroid,
                                                                          FitLoss loss) const {
  // Starts near the floor (a landed pad) and 1.5 m below and above the anchors' mean height (a
  // body at rest in the air): anchors in a narrow height band mirror the height, and only a start
  // on each side lets the ambiguity check see both (a start at the mean height itself may slide to
  // either side: a body above three anchors at one height was fitted at its mirror image without
  // refusal, StaticInitializer.CoplanarAnchors…).
  std::vector<double> z_starts{0.5, centroid.z() - 1.5, centroid.z() + 1.5};
  if (height_prior_) z_starts.push_back(height_prior_->z_m);
  std::vector<FitMinimum> minima;
  for (const double z0 : z_starts)
    for (int sx = -1; sx <= 1; ++sx)
      for (int sy = -1; sy <= 1; ++sy)
        for (int k = 0; k < 4; ++k) {
          Eigen::Vector3d p = centroid + Eigen::Vector3d(2.0 * sx, 2.0 * sy, 0.0);
          p.z() = z0;
          double yaw = k * 0.5 * M_PI;
          const double c = solveFit(R_rp, use, p, yaw, nullptr, loss);
          if (std::isfinite(c)) minima.push_back({c, p, yaw});
        }
  return minima;
}

std::vector<StaticInitializer::FitMinimum> StaticInitializer::refineDistinct(const Eigen::Matrix3d& R_rp,
                                                                            const std::vector<bool>& use,
                                                                            const std::vector<FitMinimum>& starts) const {
  std::vector<FitMinimum> distinct, refined;
  for (const FitMinimum& m : starts) {
    const bool seen = std::any_of(distinct.begin(), distinct.end(), [&](const FitMinimum& d) {
      return (d.p - m.p).norm() < 0.05 && std::abs(std::remainder(d.yaw - m.yaw, 2.0 * M_PI)) < 2.0 * kDeg;
    });
    if (!seen) distinct.push_back(m);
  }
  for (FitMinimum m : distinct) {
    m.cost = solveFit(R_rp, use, m.p, m.yaw, nullptr, FitLoss::kHuber);
    if (std::isfinite(m.cost)) refined.push_back(m);
  }
  return refined;
}

double StaticInitializer::rangeResidual(size_t i, const Eigen::Matrix3d& R, const Eigen::Vector3d& p) const {
  const InitRange& r = ranges_[i];
  return r.d_m - (setup_.abs_anchor_positions.at(r.anchor) - p - R * setup_.rel_tag_positions.at(r.tag)).norm();
}

int StaticInitializer::markInliers(const Eigen::Matrix3d& R_rp, const FitMinimum& at, std::vector<bool>& use) const {
  const Eigen::Matrix3d R = rotZ(at.yaw) * R_rp;
  int n = 0;
  for (size_t i = 0; i < ranges_.size(); ++i) {
    use[i] = std::abs(rangeResidual(i, R, at.p)) <= options_.init.range_init_outlier_m;
    n += use[i] ? 1 : 0;
  }
  return n;
}

bool StaticInitializer::fitPoseToRanges(const Eigen::Matrix3d& R_rp, Eigen::Vector3d& p_out, double& yaw_out,
                                        Eigen::Matrix4d& cov_out, double& rms_out, int& n_used) {
  waiting_for_.clear();
  height_prior_ = heightPrior(R_rp);
  std::set<SensorId> anchors;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& r : ranges_) anchors.insert(r.anchor);
  if (anchors.size() < 3) return false;
  for (SensorId a : anchors) centroid += setup_.abs_anchor_positions.at(a);
  centroid /= static_cast<double>(anchors.size());
  const auto lowest = [](const std::vector<FitMinimum>& m) {
    return *std::min_element(m.begin(), m.end(), [](const FitMinimum& x, const FitMinimum& y) { return x.cost < y.cost; });
  };

  // Two passes. The first, Cauchy over every range from a grid of starts, finds the minima and
  // which ranges are outliers (beyond `range_init_outlier_m` at its best minimum). The second
  // descends again from each distinct minimum over the inliers only (Huber, nearly χ² there), and
  // its costs decide: two minima must not differ by what a few NLOS ranges happen to add to each
  // (docs/robustness.md, "Outliers in the static fit").
  std::vector<bool> use(ranges_.size(), true);
  // Outside the setup's flight volume a minimum is no pose at all (a mirror image behind a wall).
  const auto inVolume = [&](std::vector<FitMinimum> m) {
    if (setup_.flight_volume && options_.flight_volume.enabled)
      std::erase_if(m, [&](const FitMinimum& x) {
        return setup_.flight_volume->distanceOutside(x.p) > options_.flight_volume.candidate_margin_m;
      });
    if (m.empty()) waiting_for_ = "every fit of the ranges lies outside the flight volume";
    return m;
  };
  std::vector<FitMinimum> minima = inVolume(searchMinima(R_rp, use, centroid, FitLoss::kCauchy));
  if (minima.empty()) return false;
  if (markInliers(R_rp, lowest(minima), use) < 4) return false;
  minima = inVolume(refineDistinct(R_rp, use, minima));
  if (minima.empty()) return false;
  const FitMinimum best = lowest(minima);
  waiting_for_ = ambiguityOf(minima, best, options_.init.ambiguity_chi2);
  if (!waiting_for_.empty()) return false;

  // The inliers at this minimum, and the refinement there.
  n_used = markInliers(R_rp, best, use);
  if (n_used < 4) return false;
  Eigen::Vector3d best_p = best.p;
  double best_yaw = best.yaw;
  solveFit(R_rp, use, best_p, best_yaw, &cov_out, FitLoss::kHuber);
  double sq = 0.0;
  std::vector<double> abs_e;
  const Eigen::Matrix3d R2 = rotZ(best_yaw) * R_rp;
  for (size_t i = 0; i < ranges_.size(); ++i) {
    if (!use[i]) continue;
    const double e = rangeResidual(i, R2, best_p);
    sq += e * e;
    abs_e.push_back(std::abs(e) / ranges_[i].sigma_m);
  }
  cov_out *= huber::varianceFactor(std::move(abs_e));  // ranges noisier than their σ
  rms_out = std::sqrt(sq / n_used);
  p_out = best_p;
  yaw_out = best_yaw;
  return best_p.allFinite() && std::isfinite(best_yaw);
}

}  // namespace meshnav::estimator
