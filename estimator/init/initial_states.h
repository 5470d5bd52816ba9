#pragma once
/// @file initial_states.h
/// @brief The instances every (re-)initialization adds to a new filter besides the IMU.
///
/// - Known-but-uncertain setup anchors (setup `abs_anchor_sigmas`): an anchor instance with mean
///   at its setup position, σ² per axis, and, with `uwb.estimate_setup_anchor_biases`, its a-priori
///   γ towards exactly known anchors and towards uncertain anchors of smaller id (one owner per
///   pair) as states, independent a priori.
/// - The tags' γ towards setup anchors (exact or uncertain) whose a-priori bias has σ_γ > 0, as
///   states of the tag instances (`uwb.estimate_tag_biases`): constant per pair, so a state rather
///   than white noise on every range.

#include "common/setup.h"
#include "estimator/core/estimator_options.h"
#include "estimator/filter/fusion_strategy.h"

namespace meshnav::estimator {

void addSetupAnchorStates(FusionStrategy& f, const SystemSetup& setup, const UwbOptions& uwb);
void addTagBiasStates(FusionStrategy& f, const SystemSetup& setup, const UwbOptions& uwb);

}  // namespace meshnav::estimator
