/// @file range_updater.cpp
/// @brief RangeUpdater: which ranges are fused and how (range_updater.h).

#include "estimator/uwb/range_updater.h"

#include <algorithm>

#include "common/chi_square.h"
#include "estimator/uwb/range_model.h"

namespace meshnav::estimator {

RangeUpdater::RangeUpdater(const UwbOptions& options, bool dah)
    : options_(options), skip_estimated_anchor_pairs_(dah && !options.dah_fuse_estimated_anchor_pairs) {
  if (options_.gate_probability > 0) gate_ = chi2Quantile(1, options_.gate_probability);
}

RangeMeasurement RangeUpdater::measurement(const RangeSample& s) const {
  RangeMeasurement z;
  z.t = s.t;
  z.a = s.id_initiator;
  z.b = s.id_responder;
  z.z_m = options_.use_corrected_range ? s.range_corr_m : s.range_m;
  z.R_m2 = s.R_m2;
  return z;
}

std::string RangeUpdater::refusal(const RangeMeasurement& z, const FusionStrategy& f, const UwbNetwork& network) const {
  const RangeModel::Status status = RangeModel::classify(z, f.state(), network);
  if (status != RangeModel::Status::Ok) return RangeModel::statusName(status);
  const auto& anchors = f.state().values<AnchorKind>();
  if (skip_estimated_anchor_pairs_ && anchors.count(z.a) && anchors.count(z.b))
    return "range_dah_anchor_pair_skipped";  // a policy, not bad input (see UwbOptions)
  if (!options_.fuse_calibrated_anchor_pairs && network.isCalibrated(z.a) && network.isCalibrated(z.b))
    return "range_calibrated_anchor_pair_skipped";  // a policy (see UwbOptions)
  return "";
}

std::optional<Linearization> RangeUpdater::linearize(const RangeMeasurement& z, const FusionStrategy& f,
                                                     const UwbNetwork& network, std::string* why) const {
  Linearization lin;
  const RangeModel::Status st = RangeModel::linearize(z, f.state(), network, &lin);
  if (st != RangeModel::Status::Ok) {
    *why = RangeModel::statusName(st);
    return std::nullopt;
  }
  lin.huber_k = options_.huber_k;
  lin.nlos_fraction = options_.nlos_fraction;
  lin.nlos_min_m = options_.nlos_min_excess_m;
  lin.nlos_mean_m = options_.nlos_mean_excess_m;
  lin.huber_max_prior_ratio = options_.huber_max_prior_ratio;
  return lin;
}

double RangeUpdater::priorRatio(const Linearization& lin, const UpdateResult& r) {
  const double nu2 = lin.residual(0) * lin.residual(0), R = lin.R(0, 0);
  return r.nis > 0.0 && R > 0.0 ? std::max(0.0, nu2 / r.nis - R) / R : 0.0;
}

}  // namespace meshnav::estimator
