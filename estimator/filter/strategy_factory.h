#pragma once
/// @file strategy_factory.h
/// @brief Creates the fusion strategy named in the options.

#include <memory>

#include "estimator/core/estimator_options.h"
#include "estimator/core/strategy_list.h"
#include "estimator/filter/fusion_strategy.h"

namespace meshnav::estimator {

/// Throws std::invalid_argument for unknown strategies. `gravity_z_sign`: see ImuPropagator.
std::unique_ptr<FusionStrategy> makeStrategy(const EstimatorOptions& options, double gravity_z_sign = -1.0);

}  // namespace meshnav::estimator
