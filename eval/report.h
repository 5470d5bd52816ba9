#pragma once
/// @file report.h
/// @brief Human and machine readable output of evaluations: aligned console tables, metrics.yaml,
/// errors.csv, anchors_eval.csv (input of the plot script), and the multi-run (paper-style) table.

#include <string>
#include <vector>

#include "eval/range_statistics.h"
#include "eval/reference_statistics.h"
#include "eval/run_evaluation.h"

namespace meshnav::eval {

/// A table whose columns are right-aligned to their widest cell; prints as plain text or Markdown.
class TextTable {
 public:
  explicit TextTable(std::vector<std::string> header) : header_(std::move(header)) {}
  void addRow(std::vector<std::string> row) { rows_.push_back(std::move(row)); }
  /// Horizontal rule before the next row (plain text only).
  void addRule() { rules_.push_back(rows_.size()); }
  /// No rows (only the header).
  bool empty() const { return rows_.empty(); }
  std::string plain() const;
  std::string markdown() const;

 private:
  std::vector<std::string> header_;
  std::vector<std::vector<std::string>> rows_;
  std::vector<size_t> rules_;
};

/// "0.123" with `decimals`; "–" for NaN.
std::string formatNumber(double v, int decimals = 3);

/// Results table of one run (pose accuracy, consistency, anchors), as printed by meshnav_eval.
std::string formatRunReport(const RunEvaluation& ev);

/// metrics.yaml: every figure of the report, machine readable (null for unavailable values).
void writeMetricsYaml(const RunEvaluation& ev, const std::string& path);
/// The same content as JSON.
void writeMetricsJson(const RunEvaluation& ev, const std::string& path);

/// errors.csv: t, position error xyz [m], its ±3σ [m], orientation error xyz [deg], its ±3σ
/// [deg], NEES, and whether the sample entered the metrics.
void writeErrorsCsv(const RunEvaluation& ev, const std::string& path);
/// The same rows for the smoothed estimate (errors_smoothed.csv); nothing when there is none.
void writeSmoothedErrorsCsv(const RunEvaluation& ev, const std::string& path);

/// anchors_eval.csv: per anchor true, initial and final position, errors, NEES (for the plots).
void writeAnchorsEvalCsv(const RunEvaluation& ev, const std::string& path);

/// One evaluated run of a batch.
struct BatchEntry {
  std::string name;  ///< e.g. "seed01"
  RunEvaluation ev;
};

/// The paper-style table (Tab. III): per run pos RMSE, ori RMSE, ANEES pos/ori and per calibrated
/// anchor the initial (★) and final error, their means; last row: mean over runs.
TextTable makeBatchTable(const std::vector<BatchEntry>& entries);

/// The anchors of a batch in one row (issue 10): estimated anchors with truth, mean initial (★)
/// and final error [m], their ratio, how many initial and final beliefs have NEES ≤ the 99.7 %
/// χ²(3) bound 13.93, and the median final NEES.
TextTable makeBatchAnchorSummary(const std::vector<BatchEntry>& entries);

/// Range statistics table; `reference` may be empty; `truth_pairs` (simulated γ, β, σ) may be empty.
TextTable makeRangeStatsTable(const std::map<std::pair<SensorId, SensorId>, PairRangeStats>& stats,
                              const std::map<std::pair<SensorId, SensorId>, ReferencePairStats>& reference,
                              const std::vector<PairBias>& truth_pairs);

}  // namespace meshnav::eval
