#pragma once
/// @file uncertain_anchors.h
/// @brief The "known but uncertain" anchors of the modular-estimator evaluation (issue 3): anchors
/// written to setup.yaml at truth + N(0, σ² I) with their position σ, so that the estimator holds
/// them as instances and refines them online, together with a-priori pair biases for every pair
/// that involves an anchor (like the exactly known 101–104 have).

#include <cstdint>

#include "common/dataset.h"

namespace meshnav::sim {

struct UwbHardwareOptions;

struct UncertainAnchorOptions {
  double sigma_m = 0.3;          ///< position error σ per axis, also written as the prior σ [m]
  bool include_known = false;    ///< also perturb the anchors setup.yaml already knows exactly (101–104)
  uint64_t seed = 1;             ///< error draw (the sequence seed)
};

/// Perturbs the anchors of `ds.truth` (those not already in setup.yaml, or all with
/// `include_known`) into `ds.setup` with σ, and adds the a-priori calibrated bias of every pair
/// with an anchor that setup.yaml does not have yet (tag–tag pairs excluded). Every anchor draws
/// its error whether perturbed or not, so the errors of 106–110 do not depend on `include_known`.
/// Throws std::invalid_argument without truth or with σ outside (0, 10) m.
/// @return the number of anchors written with a σ.
int makeAnchorsUncertain(Dataset& ds, const UncertainAnchorOptions& o, const UwbHardwareOptions& hardware,
                         double sigma_range_m);

}  // namespace meshnav::sim
