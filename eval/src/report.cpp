#include "eval/report.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "eval/baseline_report.h"
#include "eval/chi_square.h"

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

namespace {

std::string fmtOpt(const std::optional<double>& v, int decimals) { return v ? formatNumber(*v, decimals) : "–"; }

std::string fmtBounds(const ChiSquareBounds& b, int decimals = 2) {
  if (!std::isfinite(b.lower)) return "–";
  return "[" + formatNumber(b.lower, decimals) + ", " + formatNumber(b.upper, decimals) + "]";
}

std::string fmtPercent(double v) { return std::isfinite(v) ? formatNumber(100.0 * v, 1) + " %" : "–"; }

/// A number node ("%.6g"), or null when not finite.
YAML::Node num(double v) {
  if (!std::isfinite(v)) return YAML::Node(YAML::NodeType::Null);
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return YAML::Node(std::string(buf));
}
YAML::Node optNum(const std::optional<double>& v) { return v ? num(*v) : YAML::Node(YAML::NodeType::Null); }
/// A time stamp node to the microsecond ("%.6f"): "%.6g" would turn a recording's Unix seconds
/// (1664959690.648354) into 1.66496e+09.
YAML::Node timeNum(double t_s) {
  if (!std::isfinite(t_s)) return YAML::Node(YAML::NodeType::Null);
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.6f", t_s);
  return YAML::Node(std::string(buf));
}
YAML::Node vec(const Eigen::Vector3d& v) {
  YAML::Node n;
  for (int i = 0; i < 3; ++i) n.push_back(num(v[i]));
  n.SetStyle(YAML::EmitterStyle::Flow);
  return n;
}
YAML::Node pairNode(double a, double b) {
  YAML::Node n;
  n.push_back(num(a));
  n.push_back(num(b));
  n.SetStyle(YAML::EmitterStyle::Flow);
  return n;
}
YAML::Node statsNode(const ErrorStats& s, const std::string& unit) {
  YAML::Node n;
  n["n_samples"] = s.n;
  n["rmse_" + unit] = num(s.rmse);
  n["armse_" + unit] = num(s.armse);
  n["max_" + unit] = num(s.max);
  n["rmse_xyz_" + unit] = vec(s.rmse_axes);
  n["n_nees"] = s.n_nees;
  n["anees"] = num(s.anees);
  n["anees_bounds"] = pairNode(s.anees_bounds.lower, s.anees_bounds.upper);
  n["anees_within_bounds"] = std::isfinite(s.anees) && s.anees_bounds.contains(s.anees);
  n["fraction_nees_within_single_bounds"] = num(s.frac_nees_in_single_bounds);
  return n;
}

/// JSON text of a node built by metricsNode (scalars that parse as numbers or booleans are
/// written bare, null as null, everything else as a string).
void toJson(const YAML::Node& n, std::ostream& os, int indent) {
  const std::string pad(indent, ' ');
  switch (n.Type()) {
    case YAML::NodeType::Null:
    case YAML::NodeType::Undefined: os << "null"; return;
    case YAML::NodeType::Scalar: {
      const std::string s = n.Scalar();
      char* end = nullptr;
      std::strtod(s.c_str(), &end);
      if (!s.empty() && end && *end == '\0' && s != "nan" && s != "inf" && s != "-inf") {
        os << s;
      } else if (s == "true" || s == "false") {
        os << s;
      } else {
        os << '"';
        for (char c : s) {
          if (c == '"' || c == '\\') os << '\\' << c;
          else if (c == '\n') os << "\\n";
          else os << c;
        }
        os << '"';
      }
      return;
    }
    case YAML::NodeType::Sequence: {
      os << "[";
      for (size_t i = 0; i < n.size(); ++i) {
        if (i) os << ", ";
        toJson(n[i], os, indent + 2);
      }
      os << "]";
      return;
    }
    case YAML::NodeType::Map: {
      os << "{\n";
      size_t i = 0;
      for (const auto& kv : n) {
        os << pad << "  \"" << kv.first.Scalar() << "\": ";
        toJson(kv.second, os, indent + 2);
        os << (++i < n.size() ? ",\n" : "\n");
      }
      os << pad << "}";
      return;
    }
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// One run

std::string formatRunReport(const RunEvaluation& ev) {
  std::ostringstream os;
  const auto& m = ev.trajectory;
  const double conf = ev.options.confidence;
  os << "meshnav evaluation\n  dataset: " << ev.dataset_dir << "\n  run:     " << ev.run_dir << "\n";
  os << "  samples: " << m.n_associated << " associated with ground truth, " << m.n_selected
     << " evaluated";
  if (m.n_selected > 0) os << " (t " << formatNumber(m.t_first_s, 2) << " – " << formatNumber(m.t_last_s, 2) << " s)";
  os << "; skip first " << formatNumber(ev.options.skip_first_s, 1) << " s; only flying: "
     << (ev.options.only_flying && ev.has_flight_state ? "yes" : "no") << "\n";
  os << formatAlignmentAndBaseline(ev);

  if (m.n_selected > 0) {
    const std::string ci = formatNumber(100.0 * conf, 0) + " % bounds";
    TextTable t({"pose error", "RMSE", "ARMSE", "max", "RMSE x", "RMSE y", "RMSE z", "ANEES",
                 "ANEES " + ci, "NEES in χ²(3) " + formatNumber(100.0 * conf, 0) + " %"});
    auto row = [&](const std::string& name, const ErrorStats& s, int dec) {
      t.addRow({name, formatNumber(s.rmse, dec), formatNumber(s.armse, dec), formatNumber(s.max, dec), formatNumber(s.rmse_axes.x(), dec),
                formatNumber(s.rmse_axes.y(), dec), formatNumber(s.rmse_axes.z(), dec), formatNumber(s.anees, 2),
                fmtBounds(s.anees_bounds), fmtPercent(s.frac_nees_in_single_bounds)});
    };
    row("position [m]", m.position, 3);
    row("orientation [deg]", m.orientation, 2);
    os << t.plain();
    os << "  (RMSE = √mean‖e‖², ARMSE = mean‖e‖ as cnspy's ARMSE; NEES is χ²(3) if consistent;\n"
       << "   ANEES over " << m.position.n_nees << " samples with covariance)\n\n";
  } else {
    os << "  pose metrics: not available\n\n";
  }

  if (ev.anchors) {
    const auto single = aneesBounds(1, 3, conf);
    TextTable t({"anchor", "kind", "rows", "initial err [m]", "final err [m]", "NEES initial",
                 "NEES final", "true position [m]"});
    for (const auto& a : ev.anchors->anchors) {
      std::string pos = a.has_truth ? "[" + formatNumber(a.p_true.x(), 2) + ", " + formatNumber(a.p_true.y(), 2) + ", " +
                                          formatNumber(a.p_true.z(), 2) + "]"
                                    : "no truth";
      t.addRow({std::to_string(a.id), a.known ? "known" : "estimated", std::to_string(a.n_estimates),
                a.has_truth ? formatNumber(a.initial_error_m, 3) : "–", a.has_truth ? formatNumber(a.final_error_m, 3) : "–",
                fmtOpt(a.initial_nees, 2), fmtOpt(a.final_nees, 2), pos});
    }
    t.addRule();
    t.addRow({"mean", "estimated", std::to_string(ev.anchors->n_estimated),
              formatNumber(ev.anchors->mean_initial_error_m, 3), formatNumber(ev.anchors->mean_final_error_m, 3), "", "", ""});
    os << t.plain();
    os << "  (single NEES, 3 dof: " << formatNumber(100.0 * conf, 0) << " % interval " << fmtBounds(single, 3)
       << ", 99.7 % threshold " << formatNumber(chi2Quantile(3, 0.997), 2) << ")\n\n";
  } else {
    os << "  anchor errors: not available\n\n";
  }
  for (const auto& n : ev.notes) os << "  note: " << n << "\n";
  if (!ev.diagnostics.empty()) {
    os << "  input diagnostics:";
    for (const auto& [k, v] : ev.diagnostics) os << " " << k << "=" << v;
    os << "\n";
  }
  return os.str();
}

YAML::Node metricsNode(const RunEvaluation& ev) {
  YAML::Node root;
  root["dataset"] = ev.dataset_dir;
  root["run"] = ev.run_dir;
  YAML::Node opt;
  opt["skip_first_s"] = num(ev.options.skip_first_s);
  opt["only_flying"] = ev.options.only_flying && ev.has_flight_state;
  opt["max_gt_gap_s"] = num(ev.options.max_gt_gap_s);
  opt["confidence"] = num(ev.options.confidence);
  root["options"] = opt;
  root["definitions"] =
      "errors are truth minus estimate; orientation error dtheta = Log(R_est^T R_true) in the body frame; "
      "rmse = sqrt(mean(|e|^2)); armse = mean(|e|) (cnspy ARMSE); nees = e^T P^-1 e (3 dof); "
      "anees_bounds = two-sided chi2(3n)/n interval at the given confidence";
  addAlignmentAndBaseline(root, ev);
  const auto& m = ev.trajectory;
  if (m.n_selected == 0) {
    root["pose"] = YAML::Node(YAML::NodeType::Null);
  } else {
    YAML::Node p;
    p["n_associated"] = m.n_associated;
    p["n_evaluated"] = m.n_selected;
    p["t_first_s"] = timeNum(m.t_first_s);
    p["t_last_s"] = timeNum(m.t_last_s);
    p["position"] = statsNode(m.position, "m");
    p["orientation"] = statsNode(m.orientation, "deg");
    root["pose"] = p;
  }
  if (!ev.anchors) {
    root["anchors"] = YAML::Node(YAML::NodeType::Null);
  } else {
    const auto& a = *ev.anchors;
    YAML::Node an;
    an["n_estimated"] = a.n_estimated;
    an["mean_initial_error_m"] = num(a.mean_initial_error_m);
    an["mean_final_error_m"] = num(a.mean_final_error_m);
    const auto single = aneesBounds(1, 3, ev.options.confidence);
    an["single_nees_bounds"] = pairNode(single.lower, single.upper);
    YAML::Node list(YAML::NodeType::Sequence);
    for (const auto& e : a.anchors) {
      YAML::Node x;
      x["id"] = e.id;
      x["known"] = e.known;
      x["n_estimates"] = e.n_estimates;
      x["p_true"] = e.has_truth ? vec(e.p_true) : YAML::Node(YAML::NodeType::Null);
      YAML::Node init, fin;
      init["t_s"] = num(e.initial.t.sec());
      init["p"] = vec(e.initial.p_AinG);
      init["error_m"] = e.has_truth ? num(e.initial_error_m) : YAML::Node(YAML::NodeType::Null);
      init["nees"] = optNum(e.initial_nees);
      fin["t_s"] = num(e.final_est.t.sec());
      fin["p"] = vec(e.final_est.p_AinG);
      fin["error_m"] = e.has_truth ? num(e.final_error_m) : YAML::Node(YAML::NodeType::Null);
      fin["nees"] = optNum(e.final_nees);
      x["initial"] = init;
      x["final"] = fin;
      list.push_back(x);
    }
    an["per_anchor"] = list;
    root["anchors"] = an;
  }
  YAML::Node notes(YAML::NodeType::Sequence);
  for (const auto& n : ev.notes) notes.push_back(n);
  root["notes"] = notes;
  YAML::Node diag(YAML::NodeType::Map);
  for (const auto& [k, v] : ev.diagnostics) diag[k] = v;
  root["diagnostics"] = diag;
  return root;
}

void writeMetricsYaml(const RunEvaluation& ev, const std::string& path) {
  YAML::Emitter out;
  out << metricsNode(ev);
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot write");
  f << out.c_str() << "\n";
}

void writeMetricsJson(const RunEvaluation& ev, const std::string& path) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot write");
  toJson(metricsNode(ev), f, 0);
  f << "\n";
}

void writeErrorsCsv(const RunEvaluation& ev, const std::string& path) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot write");
  f << "t,ep_x_m,ep_y_m,ep_z_m,sigma3_p_x_m,sigma3_p_y_m,sigma3_p_z_m,"
       "eth_x_deg,eth_y_deg,eth_z_deg,sigma3_th_x_deg,sigma3_th_y_deg,sigma3_th_z_deg,"
       "ep_norm_m,eth_angle_deg,nees_p,nees_theta,flying,selected\n";
  f.setf(std::ios::fixed);
  const double r2d = 180.0 / M_PI;
  const Timestamp t0 = ev.errors.empty() ? Timestamp{} : ev.errors.front().t;
  for (const auto& e : ev.errors) {
    f.precision(6);
    f << e.t.sec();
    f.precision(5);
    for (int i = 0; i < 3; ++i) f << "," << e.p_err_m[i];
    for (int i = 0; i < 3; ++i) f << "," << 3.0 * e.sigma_p_m[i];
    for (int i = 0; i < 3; ++i) f << "," << e.theta_err_rad[i] * r2d;
    for (int i = 0; i < 3; ++i) f << "," << 3.0 * e.sigma_theta_rad[i] * r2d;
    f << "," << e.positionErrorNorm() << "," << e.orientationErrorDeg();
    f << "," << (e.nees_p ? formatNumber(*e.nees_p, 4) : "nan") << "," << (e.nees_theta ? formatNumber(*e.nees_theta, 4) : "nan");
    f << "," << (e.flying ? 1 : 0) << "," << (isSelected(e, t0, ev.options) ? 1 : 0) << "\n";
  }
}

void writeAnchorsEvalCsv(const RunEvaluation& ev, const std::string& path) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot write");
  f << "id,known,has_truth,true_x,true_y,true_z,init_x,init_y,init_z,final_x,final_y,final_z,"
       "init_err_m,final_err_m,init_nees,final_nees\n";
  if (!ev.anchors) return;
  f.setf(std::ios::fixed);
  f.precision(5);
  for (const auto& a : ev.anchors->anchors) {
    f << a.id << "," << (a.known ? 1 : 0) << "," << (a.has_truth ? 1 : 0);
    for (int i = 0; i < 3; ++i) f << "," << (a.has_truth ? a.p_true[i] : NAN);
    for (int i = 0; i < 3; ++i) f << "," << a.initial.p_AinG[i];
    for (int i = 0; i < 3; ++i) f << "," << a.final_est.p_AinG[i];
    f << "," << (a.has_truth ? a.initial_error_m : NAN) << "," << (a.has_truth ? a.final_error_m : NAN) << ","
      << (a.initial_nees ? *a.initial_nees : NAN) << "," << (a.final_nees ? *a.final_nees : NAN) << "\n";
  }
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
