#include "calibrator/calibration_problem.h"

#include <algorithm>
#include <cmath>

namespace meshnav::calib {

CalibrationProblem::CalibrationProblem(SensorId anchor_id, std::vector<CalibObservation> observations,
                                       const std::map<SensorId, ReferencePrior>& priors,
                                       const CalibratorOptions& options)
    : anchor_id_(anchor_id), obs_(std::move(observations)) {
  std::stable_sort(obs_.begin(), obs_.end(), [](const auto& a, const auto& b) { return a.t < b.t; });
  std::map<SensorId, std::vector<int>> by_ref;
  for (int i = 0; i < static_cast<int>(obs_.size()); ++i) by_ref[obs_[static_cast<size_t>(i)].ref_id].push_back(i);

  slot_of_.assign(obs_.size(), -1);
  for (auto& [id, idx] : by_ref) {
    if (static_cast<int>(idx.size()) < options.min_measurements_per_reference) {
      ignored_.push_back(std::to_string(id) + " (" + std::to_string(idx.size()) + " ranges)");
      continue;
    }
    ReferenceSlot s;
    s.id = id;
    s.obs = idx;
    if (auto it = priors.find(id); it != priors.end()) {
      s.prior = it->second;
    } else {
      s.prior.ref_id = id;
      s.prior.sigma_gamma_m = options.gamma_prior_sigma_m;
      s.prior.sigma_beta = options.beta_prior_sigma;
    }
    // Spread of the reference positions and of its ranges decides what the reference can tell.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    double z_mean = 0.0;
    for (int i : idx) {
      mean += obs_[static_cast<size_t>(i)].p_RinG;
      z_mean += obs_[static_cast<size_t>(i)].z_m;
    }
    mean /= static_cast<double>(idx.size());
    z_mean /= static_cast<double>(idx.size());
    double spread2 = 0.0, z_var = 0.0;
    for (int i : idx) {
      spread2 += (obs_[static_cast<size_t>(i)].p_RinG - mean).squaredNorm();
      z_var += std::pow(obs_[static_cast<size_t>(i)].z_m - z_mean, 2);
    }
    spread2 /= static_cast<double>(idx.size());
    z_var /= static_cast<double>(idx.size());
    s.moving = std::sqrt(spread2) > options.moving_min_spread_m;
    s.p_mean_RinG = mean;
    s.estimate_beta = options.estimate_beta && s.moving && std::sqrt(z_var) >= options.beta_min_range_spread_m;
    const int slot = static_cast<int>(slots_.size());
    for (int i : idx) slot_of_[static_cast<size_t>(i)] = slot;
    n_used_ += static_cast<int>(idx.size());
    slots_.push_back(std::move(s));
  }
  int next = kPositionDim;
  for (size_t k = 0; k < slots_.size(); ++k) gamma_index_.push_back(next++);
  for (size_t k = 0; k < slots_.size(); ++k) beta_index_.push_back(slots_[k].estimate_beta ? next++ : -1);
  dim_ = next;
}

int CalibrationProblem::numMovingSlots() const {
  return static_cast<int>(std::count_if(slots_.begin(), slots_.end(), [](const auto& s) { return s.moving; }));
}

AnchorParams CalibrationProblem::priorParams(const Eigen::Vector3d& p) const {
  AnchorParams a;
  a.p_AinG = p;
  for (const auto& s : slots_) {
    a.gamma_m.push_back(s.prior.gamma_m);
    a.beta.push_back(s.prior.beta);
  }
  return a;
}

}  // namespace meshnav::calib
