/// meshnav_view_make_log: writes a small .lcmlog of a known flight for the view's tests
/// (view_test.sh): the vehicle flies a circle of radius 2 m about (0.5, 0) at 1.5 m height, one lap
/// per 20 s; four known anchors at the corners of the hall, anchors 106 and 107 collected by the
/// calibrator and calibrated at half time. Every message type the view shows is in it:
///   GROUND_TRUTH and POSE (the truth moved by 5 cm, covariance growing with time since the last
///   range) at --pose-rate, RANGE (tag 1 to each anchor in turn, true distance + 2 cm) at 50 Hz,
///   ANCHORS, ESTIMATOR_STATUS and CALIB_STATUS at 1 Hz.
/// Event times are the data times (µs from 1 s), as in sequence.lcmlog of ./meshnav sim.
/// --no-pose leaves POSE out (the screenshot test's check that a page without a vehicle fails).
///   meshnav_view_make_log --out FILE [--duration S] [--pose-rate HZ] [--no-pose]
#include <lcm/lcm-cpp.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/cli.h"
#include "transport/channels.h"
#include "transport/convert.h"

namespace {

using namespace meshnav;

struct Writer {
  lcm::LogFile& log;
  int64_t n = 0;
  template <class T>
  void write(channels::Channel<T> channel, Timestamp t, const T& value) {
    auto msg = transport::toWire(value);
    msg.sender_id = 4242;
    const int size = msg.getEncodedSize();
    std::vector<uint8_t> buf(size);
    msg.encode(buf.data(), 0, size);
    lcm::LogEvent ev{n++, t.us, channel.name, size, buf.data()};
    log.writeEvent(&ev);
  }
};

}  // namespace

int main(int argc, char** argv) {
  Cli cli("meshnav_view_make_log", "Writes a small .lcmlog of a known circular flight for the view's tests.");
  std::string out;
  double duration_s = 20.0, pose_rate_hz = 100.0;
  cli.optional("out", out, "the .lcmlog to write")->required();
  cli.option("duration", duration_s, "seconds of data")->check(CLI::PositiveNumber);
  cli.option("pose-rate", pose_rate_hz, "POSE and GROUND_TRUTH per second")->check(CLI::PositiveNumber);
  bool no_pose = false;
  cli.flag("no-pose", no_pose, "leave POSE out");
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  lcm::LogFile log(out, "w");
  if (!log.good()) {
    std::fprintf(stderr, "%s: cannot write\n", out.c_str());
    return 1;
  }
  Writer w{log};
  const std::vector<std::pair<SensorId, Eigen::Vector3d>> known{
      {101, {-2.5, -4.0, 0.2}}, {102, {3.0, -4.0, 2.5}}, {103, {3.0, 4.0, 0.2}}, {104, {-2.5, 4.0, 2.5}}};
  const std::vector<std::pair<SensorId, Eigen::Vector3d>> unknown{{106, {-2.0, 0.5, 1.0}}, {107, {2.8, 1.0, 3.0}}};
  const Timestamp t0 = Timestamp::fromSec(1.0);
  const double half_s = duration_s / 2;
  auto truthAt = [](double s) {
    const double a = 2 * M_PI * s / 20.0;
    return Eigen::Vector3d(0.5 + 2.0 * std::cos(a), 2.0 * std::sin(a), 1.5);
  };
  const int64_t step_us = static_cast<int64_t>(1e6 / pose_rate_hz);
  int64_t next_range_us = 0, next_status_us = 0;
  size_t range_index = 0;
  for (int64_t us = 0; us <= static_cast<int64_t>(duration_s * 1e6); us += step_us) {
    const double s = us * 1e-6;
    const Timestamp t = t0 + Duration{us};
    const Eigen::Vector3d p = truthAt(s);
    const double yaw = 2 * M_PI * s / 20.0 + M_PI / 2;
    const Eigen::Quaterniond q(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
    while (next_range_us <= us) {
      const auto& all = range_index % 6 < 4 ? known[range_index % 6] : unknown[range_index % 6 - 4];
      RangeSample r;
      r.t = t0 + Duration{next_range_us};
      r.id_initiator = 1;
      r.id_responder = all.first;
      r.range_m = (truthAt(next_range_us * 1e-6) - all.second).norm() + 0.02;
      r.range_corr_m = r.range_m;
      r.R_m2 = 0.01;
      w.write(channels::kRange, r.t, r);
      ++range_index;
      next_range_us += 20'000;
    }
    PoseSample g{t, p, q};
    w.write(channels::kGroundTruth, t, g);
    PoseEstimate e;
    e.t = t;
    e.p_IinG = p + Eigen::Vector3d(0.05, 0.0, 0.0);
    e.q_ItoG = q;
    e.v_IinG = Eigen::Vector3d(-std::sin(yaw - M_PI / 2), std::cos(yaw - M_PI / 2), 0.0) * (2 * M_PI * 2.0 / 20.0);
    e.cov_p_m2 = Eigen::Vector3d(0.01, 0.0025, 0.04).asDiagonal();
    if (!no_pose) w.write(channels::kPose, t, e);
    if (next_status_us <= us) {
      const bool calibrated = s >= half_s;
      std::vector<AnchorEstimate> anchors;
      for (const auto& [id, pa] : known) anchors.push_back({t, id, pa, Eigen::Matrix3d::Zero()});
      if (calibrated)
        for (const auto& [id, pa] : unknown)
          anchors.push_back({t, id, pa + Eigen::Vector3d(0.03, -0.02, 0.0), Eigen::Vector3d(0.01, 0.0225, 0.04).asDiagonal()});
      w.write(channels::kAnchors, t, anchors);
      EstimatorStatus st;
      st.t = t;
      st.initialized = true;
      st.strategy = "dp";
      st.health = "ok";
      st.sigma_p_max_m = 0.2;
      st.sigma_yaw_deg = 1.5;
      st.counters["gated_range"] = static_cast<int64_t>(s);
      w.write(channels::kEstimatorStatus, t, st);
      CalibStatus cs;
      cs.t = t;
      for (const auto& [id, pa] : unknown)
        cs.anchors.push_back({id, calibrated ? "calibrated" : "collecting", static_cast<int64_t>(s * 8), 4,
                              calibrated ? "" : "collecting until the mission asks"});
      w.write(channels::kCalibStatus, t, cs);
      next_status_us += 1'000'000;
    }
  }
  std::printf("%s: %lld events, %.1f s\n", out.c_str(), static_cast<long long>(w.n), duration_s);
  return 0;
}
