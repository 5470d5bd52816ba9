#include "estimator/smooth/fixed_lag_smoother.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <stdexcept>
#include <utility>
#include <vector>

namespace meshnav::estimator {

PoseEstimate poseOfBelief(const ImuBelief& b) {
  PoseEstimate e;
  e.t = b.t;
  e.p_IinG = b.x.p_IinG;
  e.v_IinG = b.x.v_IinG;
  e.q_ItoG = b.x.q_ItoG;
  e.bias_gyro_rad_s = b.x.bias_gyro_rad_s;
  e.bias_acc_m_s2 = b.x.bias_acc_m_s2;
  e.cov_p_m2 = b.P.block<3, 3>(ImuErr::kP, ImuErr::kP);
  e.cov_v = b.P.block<3, 3>(ImuErr::kV, ImuErr::kV);
  e.cov_theta_rad2 = b.P.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta);
  return e;
}

FixedLagSmoother::FixedLagSmoother(const FixedLagOptions& options, Diagnostics& diag, Sink sink)
    : options_(options), enabled_(options.enabled() && static_cast<bool>(sink)), diag_(diag), sink_(std::move(sink)) {
  if (!(options_.lag_s >= 0.0) || !(options_.period_s > 0.0))
    throw std::invalid_argument("fixed_lag: lag_s >= 0 and period_s > 0 needed");
}

void FixedLagSmoother::onPropagation(const ImuBelief& from, const ImuBelief& to, const ImuMatrix& Phi) {
  if (!enabled_ || !(to.t > from.t)) return;
  truncateAfter(from.t);  // a history that changed from `from.t` on: the replay records the new one
  if (!last_pass_ || from.t >= *last_pass_ + Duration::fromSec(options_.period_s)) {
    last_pass_ = from.t;
    startPass(from, from.t - Duration::fromSec(options_.lag_s));
  }
  records_.push_back(Record{from, to, Phi, std::nullopt, false});
  prune();
}

void FixedLagSmoother::work() {
  if (pass_) continuePass(pass_->steps);
  for (int i = 0; i < release_per_call_ && !ready_.empty(); ++i) {
    if (sink_) sink_(ready_.front());
    ready_.pop_front();
  }
}

void FixedLagSmoother::onPose(const PoseEstimate& pose) {
  if (!enabled_) return;
  if (last_emitted_ && pose.t <= *last_emitted_) {
    // Its neighbours went out already (a late IMU sample's POSE): out of order, not emitted.
    diag_.count("fixed_lag_late_pose");
    return;
  }
  marks_[pose.t.us] = pose;
}

void FixedLagSmoother::finish(const ImuBelief& last) {
  if (!enabled_) return;
  continuePass(-1);
  startPass(last, last.t);
  continuePass(-1);
  for (const auto& [us, e] : marks_) {  // after `last` (not in order processing): as the filter gave them
    diag_.count("fixed_lag_unsmoothed");
    emit(e);
  }
  release();
  marks_.clear();
  records_.clear();
}

void FixedLagSmoother::reset() {
  ready_.clear();
  records_.clear();
  marks_.clear();
  pass_.reset();
  last_pass_.reset();
  last_emitted_.reset();
}

void FixedLagSmoother::truncateAfter(Timestamp t) {
  while (!records_.empty() && records_.back().to.t > t) records_.pop_back();
  if (pass_ && pass_->s.t > t) {
    // Its next record is gone: a pass starts again at the next propagation, on the new history
    // (waiting a period instead let frequent late inputs starve the passes: lag and memory grew).
    pass_.reset();
    last_pass_.reset();
    diag_.count("fixed_lag_pass_dropped");
  }
}

bool FixedLagSmoother::smoothStep(Record& r, const ImuBelief& at_end, ImuBelief& at_start) {
  if (!r.gain && !r.gain_failed) {
    const Eigen::LLT<ImuMatrix> llt(r.to.P);
    if (llt.info() != Eigen::Success) {
      r.gain_failed = true;
    } else {
      // Cᵀ = (P⁻_b)⁻¹ Φ P⁺_a (P⁻_b and P⁺_a symmetric).
      r.gain = llt.solve(r.Phi * r.from.P).transpose();
    }
  }
  if (r.gain_failed) return false;
  const ImuMatrix& C = *r.gain;
  at_start.t = r.from.t;
  at_start.x = r.from.x;
  at_start.x.boxplus(C * at_end.x.boxminus(r.to.x));
  const ImuMatrix P = r.from.P + C * (at_end.P - r.to.P) * C.transpose();
  at_start.P = 0.5 * (P + P.transpose());
  return true;
}

void FixedLagSmoother::startPass(const ImuBelief& newest, Timestamp emit_until) {
  continuePass(-1);
  if (marks_.empty() || marks_.begin()->first > emit_until.us) return;  // nothing due
  pass_ = Pass{newest, emit_until, {}};
  // Its share per propagation: its records (back to the oldest mark) over half the propagations
  // of the last period, so that it ends within about half a period.
  auto by_end = [](const Record& r, Timestamp t) { return r.to.t < t; };
  const auto oldest = std::lower_bound(records_.begin(), records_.end(), Timestamp{marks_.begin()->first}, by_end);
  const auto period_start = std::lower_bound(records_.begin(), records_.end(),
                                             newest.t - Duration::fromSec(options_.period_s), by_end);
  const auto n_pass = records_.end() - oldest, n_period = records_.end() - period_start;
  pass_->steps = static_cast<int>(std::max<std::ptrdiff_t>(2, (2 * n_pass + n_period - 1) / std::max<std::ptrdiff_t>(1, n_period)));
  pass_->calls_per_period = static_cast<size_t>(std::max<std::ptrdiff_t>(1, n_period));
  take(newest);
}

void FixedLagSmoother::take(const ImuBelief& b) {
  if (b.t <= pass_->emit_until && marks_.count(b.t.us)) pass_->out[b.t.us] = poseOfBelief(b);
}

void FixedLagSmoother::continuePass(int max_steps) {
  if (!pass_) return;
  const int64_t oldest_us = marks_.begin()->first;  // a pass runs only while marks are due
  for (int steps = 0; max_steps < 0 || steps < max_steps; ++steps) {
    Pass& p = *pass_;
    if (p.s.t.us <= oldest_us) break;  // every mark due is behind it
    // The record ending at p.s.t (records are in time order).
    auto it = std::lower_bound(records_.begin(), records_.end(), p.s.t,
                               [](const Record& r, Timestamp t) { return r.to.t < t; });
    if (it == records_.end() || it->to.t != p.s.t) {
      // No record ends there (records pruned, a history that changed): start again from the
      // predicted belief at the end of the one before.
      if (it == records_.begin()) break;
      --it;
      diag_.count("fixed_lag_chain_restart");
      p.s = it->to;
      take(p.s);
    }
    ImuBelief prev;
    if (!smoothStep(*it, p.s, prev)) {
      diag_.count("fixed_lag_chain_restart");
      prev = it->from;
    }
    p.s = std::move(prev);
    take(p.s);
    if (max_steps >= 0 && steps + 1 == max_steps && p.s.t.us > oldest_us) return;  // more next time
  }
  endPass();
}

void FixedLagSmoother::endPass() {
  Pass p = std::move(*pass_);
  pass_.reset();
  release();  // a previous pass's poses still waiting go first (in time order)
  for (auto m = marks_.begin(); m != marks_.end() && m->first <= p.emit_until.us;) {
    if (auto found = p.out.find(m->first); found != p.out.end()) {
      emit(found->second);
    } else {  // no record boundary at its time: as the filter gave it
      diag_.count("fixed_lag_unsmoothed");
      emit(m->second);
    }
    m = marks_.erase(m);
  }
  // Its poses go out over about half a period of calls, as evenly as the POSEs came: no burst.
  release_per_call_ = std::max(1, static_cast<int>((2 * ready_.size() + p.calls_per_period - 1) /
                                                   std::max<size_t>(1, p.calls_per_period)));
}

void FixedLagSmoother::prune() {
  // The passes need the records from the oldest mark on; with none, only the newest one (the next
  // mark is at its end).
  if (records_.empty()) return;
  const int64_t keep_us = marks_.empty() ? records_.back().to.t.us : marks_.begin()->first;
  while (records_.size() > 1 && records_.front().to.t.us <= keep_us) records_.pop_front();
}

void FixedLagSmoother::emit(const PoseEstimate& e) {
  last_emitted_ = e.t;
  ready_.push_back(e);
}

void FixedLagSmoother::release() {
  for (const PoseEstimate& e : ready_)
    if (sink_) sink_(e);
  ready_.clear();
}

}  // namespace meshnav::estimator
