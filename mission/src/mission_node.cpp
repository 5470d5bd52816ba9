#include "mission/mission_node.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <sstream>
#include <stdexcept>

namespace meshnav::mission {

MissionNode::MissionNode(Mission mission, MissionSinks sinks, MissionNodeOptions options)
    : mission_(std::move(mission)), sinks_(std::move(sinks)), options_(options) {
  if (!(options_.status_period_s > 0.0)) throw std::invalid_argument("mission status_period_s must be > 0");
  if (!(options_.resend_period_s >= 0.0)) throw std::invalid_argument("mission resend_period_s must be >= 0");
}

void MissionNode::setT0(Timestamp t0) {
  if (started_) {
    spdlog::warn("mission: setT0({}) after the start is ignored (t0 = {})", formatSeconds(t0), formatSeconds(*t0_));
    return;
  }
  t0_ = t0;
}

void MissionNode::onTime(Timestamp t) {
  if (!started_) {
    if (!t0_) {
      t0_ = t;
      t0_from_data_ = true;
    }
    started_ = true;
    now_ = t;
    spdlog::info("mission: started at t={} s (t0={} s), {} steps from {}", formatSeconds(t), formatSeconds(*t0_),
                 mission_.steps.size(), mission_.source.empty() ? "(code)" : mission_.source);
    if (mission_.collect_at_start && sinks_.calib_cmd) {
      CalibCommand c;
      c.t = t;
      c.action = CalibCommand::Action::Collect;
      sendCalib(c);
    }
  } else if (t < now_) {
    diag_.count("time_backwards");
    return;
  } else {
    now_ = t;
  }
  ++times_accepted_;
  resendUnanswered();
  bool ran = false;
  while (next_step_ < mission_.steps.size() &&
         now_ >= *t0_ + Duration::fromSec(mission_.steps[next_step_].t_s)) {
    runStep(mission_.steps[next_step_]);
    ++next_step_;
    ran = true;
  }
  const Duration period = Duration::fromSec(options_.status_period_s);
  if (!next_status_) next_status_ = now_;
  if (ran || now_ >= *next_status_) {
    if (now_ >= *next_status_) {
      const int64_t k = (now_ - *next_status_).us / period.us + 1;
      next_status_ = *next_status_ + Duration{k * period.us};
    }
    publishStatus();
  }
}

void MissionNode::onClockRebased(Timestamp t) {
  if (!started_) {
    onTime(t);
    return;
  }
  if (times_accepted_ <= 1 && t0_from_data_) {
    // The first data time was the only one ever accepted and the stream then agreed on another
    // time line: that first time was wrong (a pause of a real stream comes after many accepted
    // times). Start again, the start's Collect and any step issued at the wrong time included
    // (the calibrator refuses commands stamped off its data time, so they were never answered).
    diag_.count("t0_retaken");
    spdlog::warn("mission: data time jumped from t={} s to t={} s right after the first data time, which was "
                 "wrong; the mission starts again with t0 = {} s ({} step(s) issued at the wrong time again)",
                 formatSeconds(now_), formatSeconds(t), formatSeconds(t), next_step_);
    started_ = false;
    t0_.reset();
    t0_from_data_ = false;
    next_step_ = 0;
    times_accepted_ = 0;
    next_status_.reset();
    unanswered_.clear();
  } else {
    diag_.count("clock_rebased");
    spdlog::warn("mission: data time jumped from t={} s to t={} s; t0 stays {} s ({}), {} of {} steps ran",
                 formatSeconds(now_), formatSeconds(t), formatSeconds(*t0_),
                 t0_from_data_ ? "steps already ran" : "set by the user", next_step_, mission_.steps.size());
    now_ = t;
    next_status_.reset();
  }
  onTime(t);
}

void MissionNode::runStep(const MissionStep& step) {
  spdlog::info("mission: step {}/{} at data t={} s: {}", next_step_ + 1, mission_.steps.size(),
               formatSeconds(Timestamp{(now_ - *t0_).us}), step.describe());
  switch (step.action) {
    case MissionAction::Collect:
    case MissionAction::Calibrate:
    case MissionAction::Abort: {
      CalibCommand c;
      c.t = now_;
      c.action = step.action == MissionAction::Collect     ? CalibCommand::Action::Collect
                 : step.action == MissionAction::Calibrate ? CalibCommand::Action::Calibrate
                                                           : CalibCommand::Action::Abort;
      c.anchors = step.anchors;
      sendCalib(c);
      break;
    }
    case MissionAction::Remove:
      for (SensorId id : step.anchors) {
        EstimatorCommand c;
        c.t = now_;
        c.action = EstimatorCommand::Action::RemoveInstance;
        c.id = id;
        if (sinks_.estimator_cmd) sinks_.estimator_cmd(c);
      }
      break;
  }
}

void MissionNode::sendCalib(const CalibCommand& c) {
  if (!sinks_.calib_cmd) return;
  sinks_.calib_cmd(c);
  if (options_.resend_period_s > 0) unanswered_.push_back({c, c.t, 0});
}

bool MissionNode::answered(const CalibCommand& c) const {
  auto state = [&](SensorId id) {
    const auto it = calib_.find(id);
    return it == calib_.end() ? std::string() : it->second.state;
  };
  std::vector<SensorId> ids = c.anchors;
  if (ids.empty()) {
    if (calib_.empty()) return false;  // no status with anchors yet
    for (const auto& [id, a] : calib_) ids.push_back(id);
  }
  for (SensorId id : ids) {
    const std::string s = state(id);
    switch (c.action) {
      case CalibCommand::Action::Collect:
        if (s.empty() || s == "idle") return false;
        break;
      case CalibCommand::Action::Calibrate:
        if (c.anchors.empty() ? s == "collecting" : (s != "calibrated" && s != "refused")) return false;
        break;
      case CalibCommand::Action::Abort:
        if (s == "collecting") return false;
        break;
    }
  }
  return true;
}

void MissionNode::resendUnanswered() {
  const Duration period = Duration::fromSec(options_.resend_period_s);
  for (auto it = unanswered_.begin(); it != unanswered_.end();) {
    if (answered(it->cmd) || it->resends >= options_.max_resends) {
      it = unanswered_.erase(it);
      continue;
    }
    if (now_ - it->last >= period) {
      // The same command: its issue time stays, so the calibrator executes it once (a late
      // answer is no loss, and a re-sent Collect never restarts what a later step did).
      it->last = now_;
      ++it->resends;
      diag_.count("calib_cmd_resent");
      spdlog::info("mission: no answer of the calibrator yet; CALIB_CMD sent again ({})", it->resends);
      sinks_.calib_cmd(it->cmd);
    }
    ++it;
  }
}

void MissionNode::onCalibStatus(const CalibStatus& s) {
  for (const auto& a : s.anchors) {
    auto it = calib_.find(a.id);
    const bool changed = it == calib_.end() || it->second.state != a.state;
    if (changed && a.state == "refused")
      spdlog::warn("mission: calibrator refused anchor {}: {}", a.id, a.reason);
    else if (changed && a.state == "calibrated")
      spdlog::info("mission: anchor {} calibrated ({} ranges, {} references)", a.id, a.n_ranges, a.n_refs);
    calib_[a.id] = a;
  }
}

void MissionNode::onEstimatorStatus(const EstimatorStatus& s) { estimator_initialized_ = s.initialized; }

std::string MissionNode::text() const {
  std::ostringstream s;
  if (!started_) {
    s << "waiting for data";
  } else {
    s << next_step_ << "/" << mission_.steps.size() << " steps done";
    if (next_step_ > 0) s << " (last: " << mission_.steps[next_step_ - 1].describe() << ")";
    if (next_step_ < mission_.steps.size()) s << "; next: " << mission_.steps[next_step_].describe();
  }
  if (!estimator_initialized_) s << "; estimator not initialized";
  if (!calib_.empty()) {
    s << "; calibrator:";
    for (const auto& [id, a] : calib_) {
      s << " " << id << " " << a.state;
      if (a.state == "collecting") s << " (" << a.n_ranges << " ranges)";
    }
  }
  return s.str();
}

MissionStatus MissionNode::status() const {
  MissionStatus st;
  st.t = now_;
  st.wall_utime = std::chrono::duration_cast<std::chrono::microseconds>(
                      std::chrono::system_clock::now().time_since_epoch())
                      .count();
  st.step_index = static_cast<int32_t>(next_step_) - 1;
  st.n_steps = static_cast<int32_t>(mission_.steps.size());
  st.text = text();
  return st;
}

void MissionNode::publishStatus() {
  if (sinks_.status) sinks_.status(status());
}

}  // namespace meshnav::mission
