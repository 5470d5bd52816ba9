#include "closed_loop/flight_recorder.h"

namespace meshnav::closed_loop {

FlightRecorder::FlightRecorder(SystemSetup setup, Truth truth, Eigen::Vector3d pad) {
  result_.setup = std::move(setup);
  result_.truth = std::move(truth);
  result_.pad = pad;
}

void FlightRecorder::onTruth(Timestamp t, const Eigen::Vector3d& p_IinG, const Eigen::Quaterniond& q_ItoG,
                             bool airborne) {
  truth_[t.us] = {p_IinG, q_ItoG, airborne};
}

void FlightRecorder::onControlStatus(const controller::ControlStatus& s) {
  if (last_sample_t_ && s.t <= *last_sample_t_) return;  // a heartbeat repeating the last update
  last_status_ = s;
  have_status_ = true;
  const auto it = truth_.find(s.t.us);
  if (it == truth_.end()) {
    ++without_truth_;
    return;
  }
  last_sample_t_ = s.t;
  ClosedLoopSample sample;
  sample.t_s = s.t.sec();
  sample.p_true = it->second.p;
  sample.q_true = it->second.q;
  sample.airborne = it->second.airborne;
  sample.status = s;
  result_.samples.push_back(std::move(sample));
}

ClosedLoopResult FlightRecorder::finish(FlightEnd end) {
  if (have_status_) {
    end.failsafe_events = last_status_.failsafe_events;
    end.mission_complete = last_status_.mission_complete;
  }
  TruthTimeline timeline;
  timeline.reserve(truth_.size());
  for (const auto& [t, s] : truth_) timeline[t] = {s.p, s.airborne};
  result_.metrics = computeMetrics(result_, timeline, end);
  return result_;
}

}  // namespace meshnav::closed_loop
