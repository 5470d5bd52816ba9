/// @file report.cpp
/// @brief The report of one run: the console table, metrics.yaml / metrics.json, errors.csv and
/// anchors_eval.csv. TextTable and the batch and range statistics tables are in report_tables.cpp.

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

#include "common/atomic_file.h"
#include "eval/baseline_report.h"
#include "eval/chi_square.h"

namespace meshnav::eval {

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
    if (ev.smoothed && ev.smoothed->trajectory.n_selected > 0) {
      row("position [m], smoothed", ev.smoothed->trajectory.position, 3);
      row("orientation [deg], smoothed", ev.smoothed->trajectory.orientation, 2);
    }
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
  auto poseNode = [](const TrajectoryMetrics& m) {
    if (m.n_selected == 0) return YAML::Node(YAML::NodeType::Null);
    YAML::Node p;
    p["n_associated"] = m.n_associated;
    p["n_evaluated"] = m.n_selected;
    p["t_first_s"] = timeNum(m.t_first_s);
    p["t_last_s"] = timeNum(m.t_last_s);
    p["position"] = statsNode(m.position, "m");
    p["orientation"] = statsNode(m.orientation, "deg");
    return p;
  };
  root["pose"] = poseNode(ev.trajectory);
  // The smoother's estimate of the same run (estimate_smoothed.csv), when there is one.
  if (ev.smoothed && ev.smoothed->trajectory.n_selected > 0) root["pose_smoothed"] = poseNode(ev.smoothed->trajectory);
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
  writeFileAtomically(path, [&](std::ostream& f) { f << out.c_str() << "\n"; });
}

void writeMetricsJson(const RunEvaluation& ev, const std::string& path) {
  writeFileAtomically(path, [&](std::ostream& f) {
      toJson(metricsNode(ev), f, 0);
      f << "\n";
  });
}

namespace {

void writePoseErrorsCsv(const std::vector<PoseError>& errors, const EvalOptions& options, const std::string& path) {
  writeFileAtomically(path, [&](std::ostream& f) {
    f << "t,ep_x_m,ep_y_m,ep_z_m,sigma3_p_x_m,sigma3_p_y_m,sigma3_p_z_m,"
         "eth_x_deg,eth_y_deg,eth_z_deg,sigma3_th_x_deg,sigma3_th_y_deg,sigma3_th_z_deg,"
         "ep_norm_m,eth_angle_deg,nees_p,nees_theta,flying,selected\n";
    f.setf(std::ios::fixed);
    const double r2d = 180.0 / M_PI;
    const Timestamp t0 = errors.empty() ? Timestamp{} : errors.front().t;
    for (const auto& e : errors) {
      f.precision(6);
      f << e.t.sec();
      f.precision(5);
      for (int i = 0; i < 3; ++i) f << "," << e.p_err_m[i];
      for (int i = 0; i < 3; ++i) f << "," << 3.0 * e.sigma_p_m[i];
      for (int i = 0; i < 3; ++i) f << "," << e.theta_err_rad[i] * r2d;
      for (int i = 0; i < 3; ++i) f << "," << 3.0 * e.sigma_theta_rad[i] * r2d;
      f << "," << e.positionErrorNorm() << "," << e.orientationErrorDeg();
      f << "," << (e.nees_p ? formatNumber(*e.nees_p, 4) : "nan") << "," << (e.nees_theta ? formatNumber(*e.nees_theta, 4) : "nan");
      f << "," << (e.flying ? 1 : 0) << "," << (isSelected(e, t0, options) ? 1 : 0) << "\n";
    }
  });
}

}  // namespace

void writeErrorsCsv(const RunEvaluation& ev, const std::string& path) { writePoseErrorsCsv(ev.errors, ev.options, path); }

void writeSmoothedErrorsCsv(const RunEvaluation& ev, const std::string& path) {
  if (ev.smoothed) writePoseErrorsCsv(ev.smoothed->errors, ev.options, path);
}

void writeAnchorsEvalCsv(const RunEvaluation& ev, const std::string& path) {
  writeFileAtomically(path, [&](std::ostream& f) {
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
  });
}

}  // namespace meshnav::eval
