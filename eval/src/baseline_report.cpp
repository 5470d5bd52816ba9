#include "eval/baseline_report.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "eval/report.h"

namespace meshnav::eval {

namespace {

/// A "%.6g" number node, null when not finite.
YAML::Node number(double v) {
  if (!std::isfinite(v)) return YAML::Node(YAML::NodeType::Null);
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return YAML::Node(std::string(buf));
}

YAML::Node transformNode(const std::optional<RigidTransform>& T) {
  if (!T) return YAML::Node(YAML::NodeType::Null);
  YAML::Node n, R, t;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R.push_back(number(T->R_EtoT(r, c)));
  for (int i = 0; i < 3; ++i) t.push_back(number(T->t_EinT_m(i)));
  R.SetStyle(YAML::EmitterStyle::Flow);
  t.SetStyle(YAML::EmitterStyle::Flow);
  n["R_EtoT_row_major"] = R;
  n["t_EinT_m"] = t;
  return n;
}

}  // namespace

std::string formatAlignmentAndBaseline(const RunEvaluation& ev) {
  std::ostringstream os;
  os << "  alignment: " << toString(ev.alignment) << " (" << ev.alignment_reason << ")\n";
  const std::string mode = toString(ev.alignment);
  TextTable t({"position ATE [m]", "RMSE", "ARMSE", "max", "samples", "alignment"});
  auto row = [&](const std::string& name, const TrajectoryMetrics& m, bool aligned) {
    const ErrorStats& s = m.position;
    t.addRow({name, formatNumber(s.rmse), formatNumber(s.armse), formatNumber(s.max), std::to_string(m.n_selected),
              aligned ? mode : mode + " (not fitted)"});
  };
  if (ev.trajectory.n_selected > 0) row("meshnav", ev.trajectory, ev.alignment_transform.has_value());
  if (ev.baseline && ev.baseline->trajectory.n_selected > 0)
    row("multilateration", ev.baseline->trajectory, ev.baseline->transform.has_value());
  if (ev.trajectory.n_selected == 0 && !(ev.baseline && ev.baseline->trajectory.n_selected > 0)) return os.str() + "\n";
  os << t.plain();
  if (ev.baseline) {
    const auto& st = ev.baseline->stats;
    os << "  (multilateration: per tag, epochs of " << formatNumber(ev.baseline->window_s, 2) << " s, ≥ 4 known anchors, "
       << "Huber Gauss–Newton, compared as tag positions (truth pose + lever arm); " << st.epochs << " epochs, " << st.fixes << " fixes, "
       << st.too_few_anchors << " with too few anchors, " << st.degenerate << " degenerate, " << st.large_residual
       << " large residual)\n";
  }
  os << "\n";
  return os.str();
}

void addAlignmentAndBaseline(YAML::Node& root, const RunEvaluation& ev) {
  YAML::Node a;
  a["mode"] = toString(ev.alignment);
  a["reason"] = ev.alignment_reason;
  a["estimate_transform"] = transformNode(ev.alignment_transform);
  root["alignment"] = a;
  if (!ev.baseline) {
    root["baseline"] = YAML::Node(YAML::NodeType::Null);
    return;
  }
  const auto& b = *ev.baseline;
  YAML::Node n;
  n["method"] = "per-epoch multilateration, Huber IRLS Gauss-Newton, >= 4 known anchors, compared as tag positions (truth pose + lever arm)";
  n["window_s"] = number(b.window_s);
  n["epochs"] = b.stats.epochs;
  n["fixes"] = b.stats.fixes;
  n["too_few_anchors"] = b.stats.too_few_anchors;
  n["degenerate"] = b.stats.degenerate;
  n["large_residual"] = b.stats.large_residual;
  n["n_evaluated"] = b.trajectory.n_selected;
  const bool any = b.trajectory.n_selected > 0;
  n["position_rmse_m"] = number(any ? b.trajectory.position.rmse : NAN);
  n["position_armse_m"] = number(any ? b.trajectory.position.armse : NAN);
  n["transform"] = transformNode(b.transform);
  root["baseline"] = n;
}

}  // namespace meshnav::eval
