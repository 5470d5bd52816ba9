#include "closed_loop/closed_loop_io.h"

#include <filesystem>
#include <iomanip>
#include <sstream>

#include "calibrator/calibration_io.h"
#include "common/atomic_file.h"
#include "common/dataset.h"
#include "common/estimate_io.h"
#include "common/setup.h"

namespace meshnav::closed_loop {

std::string metricsYaml(const ClosedLoopMetrics& m, uint64_t seed, const std::string& mission_file) {
  std::ostringstream s;
  s << std::setprecision(6);
  s << "# meshnav fly: closed-loop flight (docs/closed_loop.md). Errors while airborne; tracking: truth\n"
    << "# against the planned setpoint (take-off, legs, return); landed_within_m: horizontal distance of\n"
    << "# the final position to the pad (-1: not landed).\n";
  s << "seed: " << seed << "\nmission: \"" << mission_file << "\"\n";
  s << "tracking_rmse_m: " << m.tracking_rmse_m << "\n";
  s << "estimation_rmse_m: " << m.estimation_rmse_m << "\n";
  s << "max_estimation_error_m: " << m.max_estimation_error_m << "\n";
  s << "crashed: " << (m.crashed ? "true" : "false") << "\n";
  if (m.crashed) s << "crash_reason: " << m.crash_reason << "\n";
  s << "landed: " << (m.landed ? "true" : "false") << "\n";
  s << "mission_complete: " << (m.mission_complete ? "true" : "false") << "\n";
  s << "landed_within_m: " << m.landed_within_m << "\n";
  s << "failsafe_events: " << m.failsafe_events << "\n";
  s << "duration_s: " << m.duration_s << "\n";
  s << "flight_time_s: " << m.flight_time_s << "\n";
  s << "anchors_initial_mean_m: " << m.anchors_initial_mean_m << "\n";
  s << "anchors_final_mean_m: " << m.anchors_final_mean_m << "\n";
  s << "anchors:\n";
  for (const auto& a : m.anchors)
    s << "  - {id: " << a.id << ", initial_error_m: " << a.initial_error_m << ", final_error_m: " << a.final_error_m
      << "}\n";
  return s.str();
}

void writeClosedLoopOutputs(const ClosedLoopResult& r, const std::string& dir, uint64_t seed,
                            const std::string& mission_file, bool with_calibration) {
  const std::filesystem::path out(dir);
  std::filesystem::create_directories(out);
  writeFileAtomically((out / "closed_loop.yaml").string(),
                      [&](std::ostream& o) { o << metricsYaml(r.metrics, seed, mission_file); });
  std::vector<PoseSample> truth;
  truth.reserve(r.samples.size());
  for (const auto& s : r.samples) truth.push_back({Timestamp::fromSec(s.t_s), s.p_true, s.q_true});
  writeTumCsv(truth, (out / "truth.csv").string());
  {
    EstimateCsvWriter w((out / "estimate.csv").string());
    for (const auto& e : r.estimates) w.write(e);
    w.flush();
  }
  {
    AnchorsCsvWriter w((out / "anchors.csv").string());
    for (const auto& a : r.final_anchors) w.write(a);
    w.flush();
  }
  writeFileAtomically((out / "planned.csv").string(), [&](std::ostream& o) {
    o << "t,x,y,z,yaw,mode,phase,waypoint,thrust,wx,wy,wz,pose_age_s,cov_trace,airborne\n";
    o << std::setprecision(9);
    for (const auto& s : r.samples) {
      const auto& st = s.status;
      o << formatSeconds(Timestamp::fromSec(s.t_s)) << ',' << st.setpoint.p_IinG.x() << ',' << st.setpoint.p_IinG.y()
        << ',' << st.setpoint.p_IinG.z() << ',' << st.setpoint.yaw_rad << ',' << controller::toString(st.mode) << ','
        << (st.phase.empty() ? "-" : st.phase) << ',' << st.waypoint << ',' << st.command.thrust_m_s2 << ','
        << st.command.w_IinI.x() << ',' << st.command.w_IinI.y() << ',' << st.command.w_IinI.z() << ','
        << st.pose_age_s << ',' << st.position_cov_trace_m2 << ',' << (s.airborne ? 1 : 0) << '\n';
    }
  });
  if (with_calibration) calib::writeCalibrationYaml(r.calibration, (out / "calibration.yaml").string());
  saveSetup(r.setup, (out / "setup.yaml").string());
  saveTruth(r.truth, (out / "truth.yaml").string());
}

}  // namespace meshnav::closed_loop
