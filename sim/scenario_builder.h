#pragma once
/// @file scenario_builder.h
/// @brief The hardware geometry of a simulated sequence (hall, tags, anchors, known anchors) from
/// its options; the paper's scenario for the default options.

#include "sim/paper_scenario.h"
#include "sim/simulation_options.h"

namespace meshnav::sim {

/// Tags (first n of): 100 and 105 at the paper's lever arms, 99 on a mast at [0, 0, 0.12] m.
/// Anchors: `AnchorLayout::generate(options.anchor_layout, options.hall(), n_known, n_unknown,
/// tags, seed)`. IMU id 1, baro id 2, baro lever arm as in the paper. The hall box is the options'.
PaperScenario buildScenario(const SimulationOptions& options);

}  // namespace meshnav::sim
