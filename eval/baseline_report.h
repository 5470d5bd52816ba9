#pragma once
/// @file baseline_report.h
/// @brief The part of the run report and of metrics.yaml that states the alignment and sets the
/// multilateration baseline beside the estimate.

#include <yaml-cpp/yaml.h>

#include <string>

#include "eval/run_evaluation.h"

namespace meshnav::eval {

/// "alignment: ..." line and the table "position ATE [m]" with the rows meshnav and
/// multilateration (RMSE, ARMSE, max, samples, alignment), plus the baseline's counters.
std::string formatAlignmentAndBaseline(const RunEvaluation& ev);

/// Adds `alignment` (mode, reason, R_EtoT, t_EinT_m) and `baseline` (counters and position
/// errors, or null) to the metrics node.
void addAlignmentAndBaseline(YAML::Node& root, const RunEvaluation& ev);

}  // namespace meshnav::eval
