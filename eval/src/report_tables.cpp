/// @file report_tables.cpp
/// @brief TextTable (plain and Markdown), formatNumber, and the multi-run tables: the batch
/// (paper-style) table, the anchors summary and the range statistics table. The report of one run
/// and its files are in report.cpp.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <sstream>

#include "eval/report.h"

namespace meshnav::eval {

// ---------------------------------------------------------------------------------------------
// TextTable

std::string TextTable::plain() const {
  std::vector<size_t> w(header_.size(), 0);
  // Width in code points, so that "σ" or "★" count as one column.
  auto len = [](const std::string& s) {
    size_t n = 0;
    for (unsigned char c : s) n += (c & 0xC0) != 0x80;
    return n;
  };
  for (size_t i = 0; i < header_.size(); ++i) w[i] = len(header_[i]);
  for (const auto& r : rows_)
    for (size_t i = 0; i < r.size() && i < w.size(); ++i) w[i] = std::max(w[i], len(r[i]));
  std::ostringstream os;
  auto line = [&](const std::vector<std::string>& r) {
    for (size_t i = 0; i < w.size(); ++i) {
      const std::string cell = i < r.size() ? r[i] : "";
      const size_t pad = w[i] - len(cell);
      if (i == 0) os << cell << std::string(pad, ' ');
      else os << "  " << std::string(pad, ' ') << cell;
    }
    os << "\n";
  };
  size_t total = 0;
  for (size_t x : w) total += x + 2;
  const std::string rule(total > 2 ? total - 2 : 0, '-');
  line(header_);
  os << rule << "\n";
  for (size_t k = 0; k < rows_.size(); ++k) {
    if (std::find(rules_.begin(), rules_.end(), k) != rules_.end()) os << rule << "\n";
    line(rows_[k]);
  }
  return os.str();
}

std::string TextTable::markdown() const {
  std::ostringstream os;
  os << "|";
  for (const auto& h : header_) os << " " << h << " |";
  os << "\n|";
  for (size_t i = 0; i < header_.size(); ++i) os << (i == 0 ? " --- |" : " ---: |");
  os << "\n";
  for (const auto& r : rows_) {
    os << "|";
    for (size_t i = 0; i < header_.size(); ++i) os << " " << (i < r.size() ? r[i] : "") << " |";
    os << "\n";
  }
  return os.str();
}

std::string formatNumber(double v, int decimals) {
  if (!std::isfinite(v)) return "–";
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(decimals);
  os << v;
  return os.str();
}

// ---------------------------------------------------------------------------------------------
// Batch

TextTable makeBatchTable(const std::vector<BatchEntry>& entries) {
  std::set<SensorId> ids;  // estimated anchors (calibrated or refined online) with truth, over all runs
  for (const auto& e : entries)
    if (e.ev.anchors)
      for (const auto& a : e.ev.anchors->anchors)
        if (!a.known && a.has_truth) ids.insert(a.id);
  std::vector<std::string> header = {"run", "pos RMSE [m]", "ori RMSE [deg]", "ANEES pos", "ANEES ori"};
  for (SensorId id : ids) {
    header.push_back("A" + std::to_string(id) + "★ [m]");
    header.push_back("A" + std::to_string(id) + " [m]");
  }
  header.push_back("mean★ [m]");
  header.push_back("mean [m]");
  TextTable t(header);

  // Column sums for the mean row (NaN entries skipped).
  std::vector<double> sum(header.size(), 0.0);
  std::vector<int> cnt(header.size(), 0);
  auto cell = [&](size_t col, double v, int dec) {
    if (std::isfinite(v)) {
      sum[col] += v;
      ++cnt[col];
    }
    return formatNumber(v, dec);
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const auto& e : entries) {
    const auto& m = e.ev.trajectory;
    const bool pose = m.n_selected > 0;
    std::vector<std::string> row = {e.name, cell(1, pose ? m.position.rmse : nan, 3),
                                    cell(2, pose ? m.orientation.rmse : nan, 2),
                                    cell(3, pose ? m.position.anees : nan, 2),
                                    cell(4, pose ? m.orientation.anees : nan, 2)};
    size_t col = 5;
    for (SensorId id : ids) {
      double init = nan, fin = nan;
      if (e.ev.anchors)
        for (const auto& a : e.ev.anchors->anchors)
          if (a.id == id && a.has_truth) {
            init = a.initial_error_m;
            fin = a.final_error_m;
          }
      row.push_back(cell(col++, init, 2));
      row.push_back(cell(col++, fin, 2));
    }
    row.push_back(cell(col++, e.ev.anchors ? e.ev.anchors->mean_initial_error_m : nan, 2));
    row.push_back(cell(col++, e.ev.anchors ? e.ev.anchors->mean_final_error_m : nan, 2));
    t.addRow(row);
  }
  t.addRule();
  std::vector<std::string> mean_row = {"mean"};
  for (size_t c = 1; c < header.size(); ++c) {
    const int dec = (c == 1) ? 3 : 2;
    mean_row.push_back(cnt[c] > 0 ? formatNumber(sum[c] / cnt[c], dec) : "–");
  }
  t.addRow(mean_row);
  return t;
}

TextTable makeBatchAnchorSummary(const std::vector<BatchEntry>& entries) {
  const double bound = chi2Quantile(3, 0.997);
  int n = 0, init_ok = 0, fin_ok = 0, n_init_nees = 0, n_fin_nees = 0;
  double sum_init = 0.0, sum_fin = 0.0;
  std::vector<double> fin_nees;
  for (const auto& e : entries) {
    if (!e.ev.anchors) continue;
    for (const auto& a : e.ev.anchors->anchors) {
      if (a.known || !a.has_truth) continue;
      ++n;
      sum_init += a.initial_error_m;
      sum_fin += a.final_error_m;
      if (a.initial_nees) {
        ++n_init_nees;
        init_ok += *a.initial_nees <= bound;
      }
      if (a.final_nees) {
        ++n_fin_nees;
        fin_ok += *a.final_nees <= bound;
        fin_nees.push_back(*a.final_nees);
      }
    }
  }
  TextTable t({"anchors", "mean★ [m]", "mean [m]", "final / initial", "NEES★ ≤ 13.93", "NEES ≤ 13.93",
               "median NEES"});
  if (n == 0) return t;
  double median = std::numeric_limits<double>::quiet_NaN();
  if (!fin_nees.empty()) {
    std::sort(fin_nees.begin(), fin_nees.end());
    const size_t m = fin_nees.size();
    median = m % 2 ? fin_nees[m / 2] : 0.5 * (fin_nees[m / 2 - 1] + fin_nees[m / 2]);
  }
  auto frac = [](int k, int of) {
    return std::to_string(k) + " / " + std::to_string(of) + " (" + formatNumber(of ? 100.0 * k / of : 0.0, 0) + " %)";
  };
  t.addRow({std::to_string(n), formatNumber(sum_init / n, 3), formatNumber(sum_fin / n, 3),
            formatNumber(sum_init > 0 ? sum_fin / sum_init : std::numeric_limits<double>::quiet_NaN(), 2),
            frac(init_ok, n_init_nees), frac(fin_ok, n_fin_nees), formatNumber(median, 1)});
  return t;
}

// ---------------------------------------------------------------------------------------------
// Range statistics

TextTable makeRangeStatsTable(const std::map<std::pair<SensorId, SensorId>, PairRangeStats>& stats,
                              const std::map<std::pair<SensorId, SensorId>, ReferencePairStats>& reference,
                              const std::vector<PairBias>& truth_pairs) {
  std::vector<std::string> header = {"pair", "ranges", "with truth", "used", "bias γ [m]", "σ [m]",
                                     "median [m]"};
  const bool ref = !reference.empty();
  const bool sim = !truth_pairs.empty();
  if (ref) {
    for (const char* h : {"ref γ [m]", "ref σ [m]", "Δγ [m]", "Δσ [m]"}) header.push_back(h);
  }
  if (sim) {
    for (const char* h : {"true γ [m]", "true β", "expected [m]", "true σ [m]", "Δ [m]", "Δσ [m]"})
      header.push_back(h);
  }
  TextTable t(header);
  for (const auto& [key, s] : stats) {
    std::vector<std::string> row = {std::to_string(s.id1) + "→" + std::to_string(s.id2),
                                    std::to_string(s.n_ranges), std::to_string(s.n_with_truth),
                                    std::to_string(s.estimate.n_used), formatNumber(s.estimate.bias_m, 3),
                                    formatNumber(s.estimate.std_m, 3), formatNumber(s.median_error_m, 3)};
    if (ref) {
      auto it = reference.find(key);
      if (it == reference.end()) {
        row.insert(row.end(), {"–", "–", "–", "–"});
      } else {
        const double g = it->second.toGamma();
        row.push_back(formatNumber(g, 2));
        row.push_back(formatNumber(it->second.noise_m, 2));
        row.push_back(formatNumber(s.estimate.bias_m - g, 3));
        row.push_back(formatNumber(s.estimate.std_m - it->second.noise_m, 3));
      }
    }
    if (sim) {
      const PairBias* pb = nullptr;
      for (const auto& p : truth_pairs)
        if (pairKey(p.a, p.b) == pairKey(s.id1, s.id2)) pb = &p;
      if (!pb) {
        row.insert(row.end(), {"–", "–", "–", "–", "–", "–"});
      } else {
        // E[z − d] = γ + (β − 1)·d̄ over the associated ranges.
        const double expected = pb->gamma_m + (pb->beta - 1.0) * s.mean_true_m;
        row.push_back(formatNumber(pb->gamma_m, 3));
        row.push_back(formatNumber(pb->beta, 4));
        row.push_back(formatNumber(expected, 3));
        row.push_back(formatNumber(pb->sigma_m, 3));
        row.push_back(formatNumber(s.estimate.bias_m - expected, 3));
        row.push_back(formatNumber(s.estimate.std_m - pb->sigma_m, 3));
      }
    }
    t.addRow(row);
  }
  return t;
}

}  // namespace meshnav::eval
