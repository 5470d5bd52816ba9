#pragma once
/// @file trajectory_factory.h
/// @brief The motion of a simulated sequence from its options (`--trajectory`, `--hall`,
/// `--duration`, `--duration-scale`, `--seed`).

#include <memory>

#include "sim/simulation_options.h"
#include "sim/trajectory.h"

namespace meshnav::sim {

/// spiral: `options.trajectory` if set, else `TrajectoryOptions::randomized(seed, scale)` with
/// scale = duration_s / 140 s when `duration_s` is set (else `duration_scale`), fitted to the hall
/// when it is not the paper's. Other kinds: drawn from the seed for `options.hall()` and a duration
/// of `duration_s` (default 140 s × duration_scale).
std::unique_ptr<Trajectory> makeTrajectory(const SimulationOptions& options);

}  // namespace meshnav::sim
