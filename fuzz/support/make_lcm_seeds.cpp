/// @file make_lcm_seeds.cpp
/// @brief Writes the seed corpus of fuzz target lcm_messages: one encoded message per channel
/// type (toLcm of a plausible value), as fuzz/corpus/lcm_messages/<type>.bin. Not part of any
/// test; rebuild the seeds after a change of lcmtypes/ with
///   cmake --build build --target fuzz_make_lcm_seeds && build/bin/fuzz_make_lcm_seeds fuzz/corpus/lcm_messages
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "transport/convert.h"

using namespace meshnav;
using namespace meshnav::transport;

namespace {

std::string g_dir;

template <class Msg>
void save(const Msg& m) {
  std::vector<uint8_t> buf(static_cast<size_t>(m.getEncodedSize()));
  m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  const std::string path = g_dir + "/" + Msg::getTypeName() + ".bin";
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(buf.data()), static_cast<std::streamsize>(buf.size()));
  std::printf("%s (%zu bytes)\n", path.c_str(), buf.size());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
    return 2;
  }
  g_dir = argv[1];
  const Timestamp t = Timestamp::fromUtime(1'700'000'000'000'000);
  save(toLcm(ImuSample{t, {0.1, -0.2, 9.81}, {0.01, 0.0, -0.02}}));
  save(toLcm(BaroSample{t, 101325.0}));
  save(toLcm(HeightSample{t, 1.27}));
  RangeSample r;
  r.t = t; r.id_initiator = 100; r.id_responder = 106; r.range_m = 4.46; r.range_corr_m = 4.45; r.R_m2 = 0.01;
  save(toLcm(r));
  save(toLcm(FlightStateSample{t, true}));
  save(toLcm(PoseSample{t, {1, 2, 3}, Eigen::Quaterniond(0.7071, 0, 0, 0.7071)}));
  PoseEstimate p;
  p.t = t; p.p_IinG = {1, 2, 3}; p.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.01;
  p.cov_v = Eigen::Matrix3d::Identity() * 0.001; p.cov_theta_rad2 = Eigen::Matrix3d::Identity() * 1e-4;
  save(toLcm(p));
  AnchorEstimate a{t, 106, {-1.772, 0.943, 3.256}, Eigen::Matrix3d::Identity() * 0.04};
  save(toLcm(a));
  PairBias b{100, 106, 0.12, 1.01, 0.1, 0.02, 0.001};
  save(toLcm(b));
  AnchorInit init;
  init.t = t; init.id = 106; init.p_AinG = a.p_AinG; init.cov_p_m2 = a.cov_p_m2; init.biases = {b};
  init.n_inliers = 120; init.n_outliers = 7;
  save(toLcm(init));
  EstimatorStatus es;
  es.t = t; es.wall_utime = t.us; es.initialized = true; es.strategy = "dp";
  es.instances = {{1, "imu", 2000, 0}, {100, "tag", 150, 3}, {106, "anchor", 80, 1}};
  es.counters = {{"gated_range", 3}, {"rejected_too_old", 0}};
  es.mean_step_us = {{"propagate", 12.5}, {"update", 40.0}};
  es.health = "ok"; es.sigma_p_max_m = 0.2; es.weak_axis_G = {0, 0, 1}; es.sigma_yaw_deg = 2.0; es.uwb_clock_offset_s = 0.03; es.uwb_clock_offset_sigma_s = 0.002;
  save(toLcm(es));
  EstimatorCommand ec;
  ec.t = t; ec.action = EstimatorCommand::Action::AddAnchor; ec.id = 106; ec.anchor = init;
  save(toLcm(ec));
  save(toLcm(CalibCommand{t, CalibCommand::Action::Calibrate, {106, 107}}));
  CalibStatus cs;
  cs.t = t; cs.wall_utime = t.us;
  cs.anchors = {{106, "calibrated", 400, 4, ""}, {107, "refused", 12, 1, "too few measurements: 12 < 50"}};
  cs.counters = {{"ranges", 412}};
  save(toLcm(cs));
  save(toLcm(MissionStatus{t, t.us, 0, 2, "step 1 of 2: calibrate 106,107"}));
  save(toLcm(t, std::vector<AnchorEstimate>{a, AnchorEstimate{t, 107, {-2.0, 1.8, 1.7}, Eigen::Matrix3d::Identity()}}));
  return 0;
}
