#include "transport/latency_recorder.h"

#include <algorithm>
#include <cmath>

namespace meshnav::transport {

LatencyStats LatencyStats::of(std::vector<double> s) {
  LatencyStats out;
  out.n = s.size();
  if (s.empty()) return out;
  std::sort(s.begin(), s.end());
  auto at = [&](double q) { return s[std::min(s.size() - 1, static_cast<size_t>(std::floor(q * static_cast<double>(s.size() - 1) + 0.5)))]; };
  out.median_us = at(0.5);
  out.p99_us = at(0.99);
  out.max_us = s.back();
  return out;
}

void LatencyRecorder::note(const std::string& channel, int64_t recv_utime) {
  ++counts_[channel];
  if (first_recv_ == 0 || recv_utime < first_recv_) first_recv_ = recv_utime;
  last_recv_ = std::max(last_recv_, recv_utime);
}

LatencyStats LatencyRecorder::imuToPose() const {
  std::vector<double> s;
  for (const auto& [u, recv_pose] : poses_)
    if (const auto imu = imu_.find(u); imu != imu_.end()) s.push_back(static_cast<double>(recv_pose - imu->second));
  return LatencyStats::of(std::move(s));
}

LatencyStats LatencyRecorder::rangeToPose() const { return toPose(ranges_, poses_, imu_); }

LatencyStats LatencyRecorder::otherRangeToPose() const { return toPose(other_ranges_, poses_, imu_); }

std::vector<LatencyRecorder::RangeAnswer> LatencyRecorder::answers(const std::vector<Stamped>& ranges,
                                                                    const std::map<int64_t, int64_t>& poses,
                                                                    const std::map<int64_t, int64_t>& imu) {
  std::vector<RangeAnswer> out;
  if (poses.empty()) return out;
  for (const Stamped& r : ranges) {
    if (r.utime < poses.begin()->first) continue;  // before the first POSE: the initialization's
    // The first POSE at or after r that left after the RANGE came (a RANGE received after the
    // POSE of its time was out is in a later one: the estimator re-ran it as a late input).
    auto pose = poses.lower_bound(r.utime);
    while (pose != poses.end() && pose->second < r.recv_utime) ++pose;
    if (pose == poses.end()) continue;
    const auto sample = imu.find(pose->first);
    if (sample == imu.end()) continue;
    out.push_back({r.utime, static_cast<double>(pose->second - std::max(r.recv_utime, sample->second)), pose->first,
                   r.recv_utime >= sample->second});
  }
  return out;
}

LatencyStats LatencyRecorder::toPose(const std::vector<Stamped>& ranges, const std::map<int64_t, int64_t>& poses,
                                     const std::map<int64_t, int64_t>& imu) {
  std::vector<double> s;
  for (const RangeAnswer& a : answers(ranges, poses, imu)) s.push_back(a.latency_us);
  return LatencyStats::of(std::move(s));
}

std::map<int64_t, size_t> LatencyRecorder::rangeToPoseOverByWindow(double bound_us, double window_s) const {
  std::map<int64_t, size_t> out;
  if (imu_.empty() || !(window_s > 0.0)) return out;
  const int64_t first = imu_.begin()->first;
  for (const RangeAnswer& a : answers(ranges_, poses_, imu_))
    if (a.latency_us > bound_us)
      ++out[static_cast<int64_t>(std::floor(static_cast<double>(a.utime - first) * 1e-6 / window_s) * window_s)];
  return out;
}

size_t LatencyRecorder::rangesAfterLastPose() const {
  int64_t last = 0;
  for (const auto& [u, recv] : poses_) last = std::max(last, recv);
  size_t n = 0;
  for (const auto* v : {&ranges_, &other_ranges_})
    for (const Stamped& r : *v) n += r.recv_utime > last;
  return n;
}

size_t LatencyRecorder::rangesBeforeFirstPose() const {
  if (poses_.empty()) return 0;
  size_t n = 0;
  for (const auto* v : {&ranges_, &other_ranges_})
    for (const Stamped& r : *v) n += r.utime < poses_.begin()->first;
  return n;
}

size_t LatencyRecorder::rangesUnanswered() const {
  // A range both before the first POSE (stamp) and after the last (receipt) is counted once.
  size_t both = 0;
  int64_t last = 0;
  for (const auto& [u, recv] : poses_) last = std::max(last, recv);
  if (!poses_.empty())
    for (const auto* v : {&ranges_, &other_ranges_})
      for (const Stamped& r : *v) both += r.utime < poses_.begin()->first && r.recv_utime > last;
  return ranges_.size() + other_ranges_.size() - rangeToPose().n - otherRangeToPose().n - rangesAfterLastPose() -
         rangesBeforeFirstPose() + both;
}

size_t LatencyRecorder::imusUnanswered() const {
  if (poses_.empty()) return 0;
  const int64_t first = poses_.begin()->first, last = poses_.rbegin()->first;
  size_t n = 0;
  for (auto it = imu_.lower_bound(first); it != imu_.end() && it->first <= last; ++it) n += poses_.count(it->first) == 0;
  return n;
}

size_t LatencyRecorder::posesWithoutImu() const {
  size_t n = 0;
  for (const auto& [u, recv] : poses_) n += imu_.count(u) == 0;
  return n;
}

std::map<std::string, double> LatencyRecorder::ratesHz() const {
  std::map<std::string, double> out;
  const double span_s = static_cast<double>(last_recv_ - first_recv_) * 1e-6;
  for (const auto& [ch, n] : counts_) out[ch] = span_s > 0.0 ? static_cast<double>(n) / span_s : 0.0;
  return out;
}

}  // namespace meshnav::transport
