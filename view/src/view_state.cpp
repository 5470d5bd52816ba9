/// @file view_state.cpp
/// @brief ViewState (view_state.h).

#include "view/view_state.h"

#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>

#include "view/json_writer.h"

namespace meshnav::view {

namespace {

double yawDeg(const Eigen::Quaterniond& q_ItoG) {
  const Eigen::Matrix3d R = q_ItoG.normalized().toRotationMatrix();
  return std::atan2(R(1, 0), R(0, 0)) * 180.0 / M_PI;
}

std::string fmt(double v, const char* spec = "%.3g") {
  char buf[48];
  std::snprintf(buf, sizeof buf, spec, v);
  return buf;
}

void writeVec3(JsonWriter& w, const Eigen::Vector3d& v) {
  w.beginArray().number(v.x()).number(v.y()).number(v.z()).endArray();
}

void writeEllipse(JsonWriter& w, const Ellipse2d& e) {
  w.beginArray().number(e.a_m, 4).number(e.b_m, 4).number(e.angle_rad, 4).endArray();
}

/// The counters of a status, non-zero ones only, as one line ("" when none).
std::string countersLine(const std::map<std::string, int64_t>& counters) {
  std::string s;
  for (const auto& [k, v] : counters) {
    if (v == 0) continue;
    if (!s.empty()) s += ", ";
    s += k + "=" + std::to_string(v);
  }
  return s;
}

}  // namespace

std::string ViewState::Anchor::state() const {
  if (!calib_state.empty()) return calib_state;
  if (!p_AinG) return "unknown";
  if (cov_m2.isZero(0.0)) return "known";
  return "estimated";
}

ViewState::ViewState(ViewStateOptions options)
    : options_(options),
      path_(8, options.path_capacity, Track::Overflow::Thin),
      truth_(4, options.path_capacity, Track::Overflow::Thin),
      residuals_(3, options.residual_capacity, Track::Overflow::DropOldest),
      residual_maker_(
          [this](SensorId id) -> const Eigen::Vector3d* {
            auto it = anchors_.find(id);
            return (it != anchors_.end() && it->second.p_AinG) ? &*it->second.p_AinG : nullptr;
          },
          [this](const RangeResidual& r) { onResidual(r); }) {}

double ViewState::rel(Timestamp t) {
  if (!t0_) t0_ = t;
  if (!t_latest_ || t > *t_latest_) t_latest_ = t;
  return (t - *t0_).sec();
}

void ViewState::setSetup(const SystemSetup& setup) {
  residual_maker_.setLeverArms(setup.rel_tag_positions);
  for (const auto& [id, p] : setup.abs_anchor_positions) {
    Anchor& a = anchors_[id];
    a.id = id;
    a.from_setup = true;
    if (!a.p_AinG) {
      a.p_AinG = p;
      const auto s = setup.abs_anchor_sigmas_m.find(id);
      a.cov_m2 = Eigen::Matrix3d::Zero();
      if (s != setup.abs_anchor_sigmas_m.end()) a.cov_m2.diagonal().setConstant(s->second * s->second);
    }
  }
}

bool ViewState::joins(const Track& track, double t, const Eigen::Vector3d& p) const {
  const size_t n = track.size();
  if (n == 0) return true;
  const Eigen::Vector3d last(track.at(n - 1, 1), track.at(n - 1, 2), track.at(n - 1, 3));
  return (p - last).norm() >= options_.path_min_step_m || t - track.at(n - 1, 0) >= options_.path_max_gap_s;
}

void ViewState::onPose(const PoseEstimate& p) {
  ++updates_;
  if (pose_ && p.t < pose_->t) {
    diag_.count("view:pose_out_of_order");  // kept off the path, which stays in time order
    return;
  }
  const double t = rel(p.t);
  const Ellipse2d e = horizontalEllipse(p.cov_p_m2, options_.ellipse_scale);
  if (joins(path_, t, p.p_IinG))
    path_.append({t, p.p_IinG.x(), p.p_IinG.y(), p.p_IinG.z(), e.a_m, e.b_m, e.angle_rad,
                  std::sqrt(std::max(0.0, p.cov_p_m2(2, 2)))});
  pose_ = p;
  ++n_poses_;
  residual_maker_.onPose(p);
}

void ViewState::onGroundTruth(const PoseSample& p) {
  ++updates_;
  if (truth_pose_ && p.t < truth_pose_->t) {
    diag_.count("view:truth_out_of_order");
    return;
  }
  const double t = rel(p.t);
  if (joins(truth_, t, p.p_IinG)) truth_.append({t, p.p_IinG.x(), p.p_IinG.y(), p.p_IinG.z()});
  truth_pose_ = p;
  ++n_truth_;
}

void ViewState::onAnchors(const std::vector<AnchorEstimate>& anchors) {
  ++updates_;
  if (!anchors.empty()) rel(anchors.front().t);
  for (auto& [id, a] : anchors_) a.in_estimator = false;
  for (const AnchorEstimate& e : anchors) {
    Anchor& a = anchors_[e.id];
    a.id = e.id;
    a.p_AinG = e.p_AinG;
    a.cov_m2 = e.cov_p_m2;
    a.in_estimator = true;
  }
}

void ViewState::onRange(const RangeSample& r) {
  ++updates_;
  rel(r.t);
  for (const auto& [id, type] : {std::pair{r.id_initiator, r.type_initiator}, std::pair{r.id_responder, r.type_responder}}) {
    if (type != UwbType::Anchor) continue;
    Anchor& a = anchors_[id];
    a.id = id;
    ++a.n_ranges;
  }
  residual_maker_.onRange(r);
}

void ViewState::onResidual(const RangeResidual& r) {
  Anchor& a = anchors_[r.anchor];
  a.last_residual_m = r.residual_m;
  ++a.n_residuals;
  a.recent_residuals_m.push_back(r.residual_m);
  while (a.recent_residuals_m.size() > options_.residual_window) a.recent_residuals_m.pop_front();
  residuals_.append({relConst(r.t), static_cast<double>(r.anchor), r.residual_m});
}

void ViewState::onEstimatorStatus(const EstimatorStatus& s) {
  estimator_status_ = s;
  std::vector<std::pair<std::string, std::string>> f;
  f.emplace_back("health", s.health + (s.health_reason.empty() ? "" : " (" + s.health_reason + ")"));
  f.emplace_back("strategy", s.strategy);
  f.emplace_back("initialized", s.initialized ? "yes" : "no");
  f.emplace_back("σp max [m]", fmt(s.sigma_p_max_m));
  f.emplace_back("σ yaw [°]", fmt(s.sigma_yaw_deg));
  f.emplace_back("instances", std::to_string(s.instances.size()));
  if (const std::string c = countersLine(s.counters); !c.empty()) f.emplace_back("counters", c);
  onStatusFields("ESTIMATOR_STATUS", s.t, std::move(f));
}

void ViewState::onCalibStatus(const CalibStatus& s) {
  std::vector<std::pair<std::string, std::string>> f;
  for (const CalibAnchorStatus& c : s.anchors) {
    Anchor& a = anchors_[c.id];
    a.id = c.id;
    a.calib_state = c.state;
    a.calib_reason = c.reason;
    f.emplace_back("anchor " + std::to_string(c.id),
                   c.state + " (" + std::to_string(c.n_ranges) + " ranges, " + std::to_string(c.n_refs) + " refs)" +
                       (c.reason.empty() ? "" : ": " + c.reason));
  }
  if (const std::string c = countersLine(s.counters); !c.empty()) f.emplace_back("counters", c);
  onStatusFields("CALIB_STATUS", s.t, std::move(f));
}

void ViewState::onMissionStatus(const MissionStatus& s) {
  onStatusFields("MISSION_STATUS", s.t,
                 {{"step", std::to_string(s.step_index + 1) + " of " + std::to_string(s.n_steps)}, {"state", s.text}});
}

void ViewState::onStatusFields(const std::string& channel, Timestamp t,
                               std::vector<std::pair<std::string, std::string>> fields) {
  ++updates_;
  // A heartbeat before any data carries t = 0 of the data clock: it does not set t0.
  if (t.us != 0 || t0_) rel(t);
  for (auto& [name, entry] : statuses_)
    if (name == channel) {
      entry = {t, std::move(fields)};
      return;
    }
  statuses_.push_back({channel, {t, std::move(fields)}});
}

std::map<std::string, int64_t> ViewState::counters() const {
  std::map<std::string, int64_t> c = diag_.snapshot();
  for (const auto& [k, v] : residual_maker_.diagnostics().snapshot()) c[k] += v;
  return c;
}

std::string ViewState::json(const ViewCursor& c) const {
  JsonWriter w;
  w.beginObject();
  w.field("updates", updates_);
  w.key("t0_utime");
  if (t0_) w.integer(t0_->us); else w.null();
  w.key("t").number(t_latest_ ? relConst(*t_latest_) : 0.0);
  w.key("source").beginObject().field("mode", source_.mode).field("description", source_.description)
      .field("speed", source_.speed).field("progress", source_.progress).field("done", source_.done).endObject();
  w.field("lever_arms", residual_maker_.hasLeverArms() ? std::string("setup") : std::string("zero"));
  w.field("ellipse_scale", options_.ellipse_scale);

  w.key("pose");
  if (pose_) {
    const Ellipse2d e = horizontalEllipse(pose_->cov_p_m2, options_.ellipse_scale);
    w.beginObject().field("t", relConst(pose_->t)).field("n", n_poses_);
    w.key("p"); writeVec3(w, pose_->p_IinG);
    w.key("v"); writeVec3(w, pose_->v_IinG);
    w.field("yaw_deg", yawDeg(pose_->q_ItoG));
    w.key("ell"); writeEllipse(w, e);
    w.field("sigma_z_m", std::sqrt(std::max(0.0, pose_->cov_p_m2(2, 2))));
    w.endObject();
  } else {
    w.null();
  }
  w.key("truth_pose");
  if (truth_pose_) {
    w.beginObject().field("t", relConst(truth_pose_->t)).field("n", n_truth_);
    w.key("p"); writeVec3(w, truth_pose_->p_IinG);
    w.field("yaw_deg", yawDeg(truth_pose_->q_ItoG)).endObject();
  } else {
    w.null();
  }
  w.key("path"); path_.write(w, c.path_epoch, c.path_rows);
  w.key("truth"); truth_.write(w, c.truth_epoch, c.truth_rows);
  w.key("residuals"); residuals_.write(w, c.residual_epoch, c.residual_rows, 5);

  w.key("anchors").beginArray();
  for (const auto& [id, a] : anchors_) {
    w.beginObject().field("id", static_cast<int64_t>(id)).field("state", a.state());
    w.key("p");
    if (a.p_AinG) writeVec3(w, *a.p_AinG); else w.null();
    w.key("ell"); writeEllipse(w, horizontalEllipse(a.cov_m2, options_.ellipse_scale));
    w.field("sigma_z_m", std::sqrt(std::max(0.0, a.cov_m2(2, 2))));
    w.field("in_estimator", a.in_estimator).field("from_setup", a.from_setup);
    w.field("reason", a.calib_reason).field("n_ranges", a.n_ranges).field("n_residuals", a.n_residuals);
    if (!a.recent_residuals_m.empty()) {
      double sum = 0.0, sq = 0.0;
      for (double r : a.recent_residuals_m) {
        sum += r;
        sq += r * r;
      }
      const double n = static_cast<double>(a.recent_residuals_m.size());
      w.field("last_residual_m", a.last_residual_m).field("mean_residual_m", sum / n)
          .field("rms_residual_m", std::sqrt(sq / n));
    }
    w.endObject();
  }
  w.endArray();

  w.key("health");
  if (estimator_status_) {
    const EstimatorStatus& s = *estimator_status_;
    w.beginObject().field("t", relConst(s.t)).field("state", s.health).field("reason", s.health_reason)
        .field("initialized", s.initialized).field("strategy", s.strategy).field("sigma_p_max_m", s.sigma_p_max_m)
        .field("sigma_yaw_deg", s.sigma_yaw_deg).endObject();
  } else {
    w.null();
  }

  w.key("statuses").beginArray();
  for (const auto& [name, entry] : statuses_) {
    w.beginObject().field("channel", name).field("t", relConst(entry.first)).key("fields").beginArray();
    for (const auto& [k, v] : entry.second) w.beginArray().string(k).string(v).endArray();
    w.endArray().endObject();
  }
  w.endArray();

  w.key("counters").beginObject();
  for (const auto& [k, v] : counters()) w.field(k, v);
  for (const auto& [k, v] : transport_counters_) w.field(k, v);
  w.endObject();
  w.endObject();
  return w.str();
}

}  // namespace meshnav::view
