#pragma once
/// @file latency_recorder.h
/// @brief What `./meshnav bench lcm` measures from the messages one probe process receives
/// (scripts/bench_lcm.sh, transport/apps/lcm_probe.cpp): every time below is the probe's receive
/// time of a message (one clock, LCM's receive thread), so no two hosts' clocks are compared.
///
///  - **IMU → POSE**: a POSE stamped u answers the IMU sample stamped u (the estimator publishes
///    one POSE per IMU sample once initialized): recv(POSE u) − recv(IMU u). This is the estimator's
///    processing plus two hops over loopback.
///  - **RANGE → POSE**: (over the ranges the estimator fuses, see `fused` below) a RANGE stamped r is in the first POSE stamped u ≥ r received after it; that POSE can only be
///    made once both the RANGE and the IMU sample u are in, so its latency is
///    recv(POSE u) − max(recv(RANGE r), recv(IMU u)): the range's update, the propagation to u and
///    the POSE, without the wait for the next IMU sample (data time, not processing). A RANGE
///    stamped before the first POSE (before the estimator initialized) is not in it: the first
///    POSE's latency is the initialization's, not a range update's (rangesBeforeFirstPose; they
///    were 24 of each vehicle's ~2 900 in the scaled fleet, answered 16-30 ms later, 0.8 %: alone
///    enough to move a p99).
/// A RANGE is marked `fused` when it is one the estimator updates with (a tag of the vehicle to an
/// anchor); the others (anchor–anchor mesh ranges, tag-to-tag ranges between vehicles), which the
/// estimator drops at once, go to otherRangeToPose, so that they do not dilute RANGE → POSE (in
/// the scaled fleet about 9 of 10 ranges a vehicle's dataset carries are mesh ranges).
/// Messages per second are counts over the first to the last receive time of all channels.
///
/// Lost messages (`./meshnav bench lcm --fleet`): an IMU sample whose data time lies between the
/// first and the last POSE and that no POSE answers (imusUnanswered: lost on its way to the
/// estimator, or its POSE lost on the way back); a POSE whose IMU sample the probe never received
/// (posesWithoutImu: an IMU lost on the way to the probe); RANGE unanswered (rangesUnanswered),
/// apart from those received after the last POSE (rangesAfterLastPose).
/// One recorder per vehicle in a fleet (the probe's --channel-prefixes).
///
/// Free of LCM: fed with (data utime, receive utime) pairs; unit-tested.

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace meshnav::transport {

/// Median, 99th percentile and maximum of a latency sample [µs] (n = 0: all zero).
struct LatencyStats {
  size_t n = 0;
  double median_us = 0.0, p99_us = 0.0, max_us = 0.0;
  static LatencyStats of(std::vector<double> samples_us);
};

class LatencyRecorder {
 public:
  void onImu(int64_t utime, int64_t recv_utime) { imu_[utime] = recv_utime; note("IMU", recv_utime); }
  void onRange(int64_t utime, int64_t recv_utime, bool fused = true) {
    (fused ? ranges_ : other_ranges_).push_back({utime, recv_utime});
    note("RANGE", recv_utime);
  }
  void onPose(int64_t utime, int64_t recv_utime) { poses_[utime] = recv_utime; note("POSE", recv_utime); }
  /// Any other channel, counted only.
  void onOther(const std::string& channel, int64_t recv_utime) { note(channel, recv_utime); }

  /// IMU → POSE over every POSE whose IMU sample was received.
  LatencyStats imuToPose() const;
  /// RANGE → POSE over every RANGE that a later POSE (and its IMU sample) answers; the others
  /// (after the last POSE, before initialization) are counted in rangesUnanswered().
  LatencyStats rangeToPose() const;
  /// The same over the ranges not marked `fused` (empty when every range was).
  LatencyStats otherRangeToPose() const;
  /// Where in the flight the RANGE → POSE tail is: the fused ranges answered later than
  /// `bound_us`, counted per `window_s` of data time; key = the window's start [s] after the first
  /// IMU sample's time (windows without one are left out).
  std::map<int64_t, size_t> rangeToPoseOverByWindow(double bound_us, double window_s) const;
  /// One fused range a later POSE answers (the probe's --samples).
  struct RangeAnswer {
    int64_t utime = 0;       ///< the range's data time
    double latency_us = 0;   ///< RANGE → POSE
    int64_t pose_utime = 0;  ///< the answering POSE's stamp (> the first IMU stamp ≥ utime: the range came after that POSE)
    bool range_last = false; ///< the RANGE came after the answering POSE's IMU sample (the latency counts from the RANGE)
  };
  /// Every fused range a later POSE answers, in range order: the sample rangeToPose() summarizes.
  std::vector<RangeAnswer> rangeToPoseSamples() const { return answers(ranges_, poses_, imu_); }
  /// RANGE, fused or not, stamped before the first POSE (the estimator was not yet initialized).
  size_t rangesBeforeFirstPose() const;
  /// RANGE, fused or not, that no later POSE answers, not counting those received after the last
  /// POSE (rangesAfterLastPose: no POSE could answer them).
  size_t rangesUnanswered() const;
  /// RANGE received after the last POSE was (the end of the data: their IMU sample's POSE had left).
  size_t rangesAfterLastPose() const;
  /// How many RANGE were marked `fused`.
  size_t fusedRanges() const { return ranges_.size(); }
  /// IMU samples stamped within [first POSE, last POSE] that no POSE of the same stamp answers.
  size_t imusUnanswered() const;
  /// POSEs whose IMU sample (same stamp) was not received.
  size_t posesWithoutImu() const;
  /// Messages per second per channel, over the span of all receive times.
  std::map<std::string, double> ratesHz() const;
  std::map<std::string, int64_t> counts() const { return counts_; }

 private:
  void note(const std::string& channel, int64_t recv_utime);
  std::map<int64_t, int64_t> imu_;    ///< utime → receive utime
  std::map<int64_t, int64_t> poses_;  ///< utime → receive utime
  struct Stamped { int64_t utime, recv_utime; };
  /// Every range of `ranges` a later POSE answers.
  static std::vector<RangeAnswer> answers(const std::vector<Stamped>& ranges, const std::map<int64_t, int64_t>& poses,
                                          const std::map<int64_t, int64_t>& imu);
  static LatencyStats toPose(const std::vector<Stamped>& ranges, const std::map<int64_t, int64_t>& poses,
                             const std::map<int64_t, int64_t>& imu);
  std::vector<Stamped> ranges_, other_ranges_;
  std::map<std::string, int64_t> counts_;
  int64_t first_recv_ = 0, last_recv_ = 0;
};

}  // namespace meshnav::transport
