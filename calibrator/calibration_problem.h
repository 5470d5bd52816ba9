#pragma once
/// @file calibration_problem.h
/// @brief The observations of one unknown anchor x grouped by reference device, and the layout of
/// the unknowns x = [p_AinG (3), γ_R (one per reference), β_R (one per reference where observable)].

#include <map>
#include <string>
#include <vector>

#include "calibrator/calibration_types.h"
#include "calibrator/calibrator_options.h"

namespace meshnav::calib {

/// One reference device R of the anchor: its observations (time-sorted indices) and what of its
/// pair biases is estimated.
struct ReferenceSlot {
  SensorId id = 0;
  ReferencePrior prior;
  bool moving = false;         ///< positions spread more than `moving_min_spread_m`: carries geometry
  Eigen::Vector3d p_mean_RinG = Eigen::Vector3d::Zero();  ///< mean of its positions (a stationary one's place) [m]
  bool estimate_beta = false;  ///< β_R free (moving and ranges spread enough); else fixed to prior
  std::vector<int> obs;        ///< indices into observations(), sorted by time
};

/// Value of the unknowns; gamma/beta are indexed by reference slot.
struct AnchorParams {
  Eigen::Vector3d p_AinG = Eigen::Vector3d::Zero();
  std::vector<double> gamma_m;
  std::vector<double> beta;
};

class CalibrationProblem {
 public:
  static constexpr int kPositionIndex = 0;  ///< p_AinG occupies [0, 3) of the stacked unknowns
  static constexpr int kPositionDim = 3;

  /// Groups `observations` (any order) by reference. A reference with fewer than
  /// `min_measurements_per_reference` ranges is ignored (its observations get slot −1).
  /// `priors` overrides the default γ/β prior of a reference (a-priori calibrated pair).
  CalibrationProblem(SensorId anchor_id, std::vector<CalibObservation> observations,
                     const std::map<SensorId, ReferencePrior>& priors, const CalibratorOptions& options);

  SensorId anchorId() const { return anchor_id_; }
  const std::vector<CalibObservation>& observations() const { return obs_; }
  const std::vector<ReferenceSlot>& slots() const { return slots_; }
  /// Slot of observation i, −1 when its reference is ignored.
  int slotOf(int i) const { return slot_of_[static_cast<size_t>(i)]; }
  /// Number of observations with a slot.
  int numUsed() const { return n_used_; }
  int numMovingSlots() const;
  /// References ignored for having too few ranges ("id (n ranges)"), for messages.
  const std::vector<std::string>& ignoredReferences() const { return ignored_; }

  /// Size of the stacked unknown vector.
  int dim() const { return dim_; }
  int gammaIndex(int slot) const { return gamma_index_[static_cast<size_t>(slot)]; }
  /// −1 when β of the slot is fixed.
  int betaIndex(int slot) const { return beta_index_[static_cast<size_t>(slot)]; }

  /// Params with γ, β at their prior means and p_AinG = `p`.
  AnchorParams priorParams(const Eigen::Vector3d& p) const;

 private:
  SensorId anchor_id_;
  std::vector<CalibObservation> obs_;
  std::vector<ReferenceSlot> slots_;
  std::vector<int> slot_of_;
  std::vector<int> gamma_index_, beta_index_;
  std::vector<std::string> ignored_;
  int n_used_ = 0;
  int dim_ = kPositionDim;
};

}  // namespace meshnav::calib
