#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "sim/imu_simulator.h"
#include "sim/hall.h"
#include "sim/spiral_trajectory.h"
#include "sim/walk_trajectory.h"
#include "trajectory_checks.h"

using namespace meshnav::sim;

using namespace meshnav::sim::test;

TEST(SimImuSimulator, NoiseFreeImuIntegratesBackToTheTrajectory) {
  const SpiralTrajectory tr(TrajectoryOptions::randomized(2));
  ImuSimulator sim(ImuNoiseOptions::noiseless(), 2);
  const auto imu = sim.simulate(tr, tr.duration());
  ASSERT_EQ(imu.size(), static_cast<size_t>(std::floor(tr.duration() * 200 + 1e-9)) + 1);
  // Windows of 10 s: take-off (from the pad), spiral, spiral end + landing start.
  for (double t0 : {2.0, 40.0, tr.options().spiral_end_s - 5.0, tr.touchdownTime() - 8.0}) {
    const auto k0 = static_cast<size_t>(std::llround(t0 * 200));
    const size_t k1 = k0 + 2000;
    ASSERT_LT(k1, imu.size());
    const NavState x = integrate(imu, k0, k1, trueState(tr.evaluate(imu[k0].t.sec())));
    const auto truth = tr.evaluate(imu[k1].t.sec());
    EXPECT_LT((x.p - truth.p_IinG).norm(), 0.01) << "window from " << t0;
    EXPECT_LT((x.p - truth.p_IinG).norm(), 1e-4) << "window from " << t0;  // in fact far better than 1 cm
    EXPECT_LT((x.v - truth.v_IinG).norm(), 1e-4) << "window from " << t0;
    EXPECT_LT(toQuat(x.q).angularDistance(truth.q_ItoG), 1e-6) << "window from " << t0;
  }
}

TEST(SimImuSimulator, IdealReadingIsSpecificForceInBodyFrame) {
  const SpiralTrajectory tr(TrajectoryOptions::randomized(1));
  // On the pad the accelerometer reads +g along body z and the gyro zero.
  const auto pad = ImuSimulator::ideal(tr.evaluate(1.0));
  EXPECT_LT((pad.acc_m_s2 - Eigen::Vector3d(0, 0, 9.81)).norm(), 1e-12);
  EXPECT_LT(pad.gyro_rad_s.norm(), 1e-15);
  // In flight: R f + g = a.
  const auto s = tr.evaluate(50.0);
  const auto m = ImuSimulator::ideal(s);
  EXPECT_LT((s.R_ItoG * m.acc_m_s2 + Eigen::Vector3d(0, 0, -9.81) - s.a_IinG).norm(), 1e-12);
  // Thrust is along body z only (a quadrotor): no lateral specific force.
  EXPECT_LT(m.acc_m_s2.head<2>().norm(), 1e-12);
}

TEST(SimImuSimulator, NoiseAndBiasHaveTheConfiguredStatistics) {
  const SpiralTrajectory tr(TrajectoryOptions::randomized(1));
  ImuNoiseOptions opt;  // defaults: 2e-3 m/s²/√Hz, 2e-4 rad/s/√Hz at 200 Hz
  ImuSimulator sim(opt, 9);
  const auto imu = sim.simulate(tr, tr.duration());
  const double dt = 1.0 / opt.rate_hz;
  // Consecutive differences on the pad (first 4 s): variance 2σ_d² + σ_w² dt ≈ 2σ_d².
  double s_acc = 0, s_gyro = 0;
  int n = 0;
  Eigen::Vector3d mean_acc_err = Eigen::Vector3d::Zero(), mean_gyro_err = Eigen::Vector3d::Zero();
  for (size_t k = 1; imu[k].t.sec() < 4.0; ++k, ++n) {
    s_acc += (imu[k].acc_m_s2 - imu[k - 1].acc_m_s2).squaredNorm();
    s_gyro += (imu[k].gyro_rad_s - imu[k - 1].gyro_rad_s).squaredNorm();
    const auto ideal = ImuSimulator::ideal(tr.evaluate(imu[k].t.sec()));
    mean_acc_err += imu[k].acc_m_s2 - ideal.acc_m_s2;
    mean_gyro_err += imu[k].gyro_rad_s - ideal.gyro_rad_s;
  }
  const double sigma_acc = std::sqrt(s_acc / (6.0 * n)), sigma_gyro = std::sqrt(s_gyro / (6.0 * n));
  EXPECT_NEAR(sigma_acc, opt.acc_noise_density / std::sqrt(dt), 0.05 * opt.acc_noise_density / std::sqrt(dt));
  EXPECT_NEAR(sigma_gyro, opt.gyro_noise_density / std::sqrt(dt), 0.05 * opt.gyro_noise_density / std::sqrt(dt));
  // The mean error over the pad phase is the (slowly walking) initial bias.
  EXPECT_LT((mean_acc_err / n - sim.initialAccBias()).norm(), 0.01);
  EXPECT_LT((mean_gyro_err / n - sim.initialGyroBias()).norm(), 1e-3);
  EXPECT_GT(sim.initialAccBias().norm(), 0.0);
  // Bias random walk: after T seconds the change has σ = σ_w √T per axis (loose 4σ bound).
  const double T = tr.duration();
  EXPECT_LT((sim.finalAccBias() - sim.initialAccBias()).cwiseAbs().maxCoeff(), 4 * opt.acc_bias_rw * std::sqrt(T));
  EXPECT_GT((sim.finalAccBias() - sim.initialAccBias()).norm(), 0.0);
}

TEST(SimImuSimulator, SameSeedSameSamples) {
  const SpiralTrajectory tr(TrajectoryOptions::randomized(1, 0.2));
  ImuSimulator a(ImuNoiseOptions{}, 5), b(ImuNoiseOptions{}, 5), c(ImuNoiseOptions{}, 6);
  const auto sa = a.simulate(tr, 10.0), sb = b.simulate(tr, 10.0), sc = c.simulate(tr, 10.0);
  ASSERT_EQ(sa.size(), sb.size());
  for (size_t k = 0; k < sa.size(); ++k) {
    EXPECT_EQ(sa[k].acc_m_s2, sb[k].acc_m_s2);
    EXPECT_EQ(sa[k].gyro_rad_s, sb[k].gyro_rad_s);
  }
  EXPECT_NE(sa[10].acc_m_s2, sc[10].acc_m_s2);
}

TEST(SimImuSimulator, AxisErrorsScaleAndTiltTheReadingsAndLeaveTheOtherDrawsAsTheyWere) {
  // Readings T ideal + b + n: noise-free, the axis matrix is the reading's map of the ideal one.
  const SpiralTrajectory tr(TrajectoryOptions::randomized(1));
  ImuNoiseOptions opt = ImuNoiseOptions::noiseless();
  opt.scale_sigma = 0.01;
  opt.misalignment_sigma_rad = 0.5 * M_PI / 180.0;
  ImuSimulator sim(opt, 4);
  const auto imu = sim.simulate(tr, 60.0);
  const Eigen::Matrix3d Ta = sim.accAxes(), Tg = sim.gyroAxes();
  EXPECT_FALSE(Ta.isApprox(Eigen::Matrix3d::Identity(), 1e-6));
  EXPECT_FALSE(Ta.isApprox(Tg, 1e-6));  // each sensor its own axes
  for (const Eigen::Matrix3d& T : {Ta, Tg}) {
    EXPECT_LT((T.diagonal() - Eigen::Vector3d::Ones()).cwiseAbs().maxCoeff(), 5 * opt.scale_sigma);
    EXPECT_LT((T - Eigen::Matrix3d(T.diagonal().asDiagonal())).cwiseAbs().maxCoeff(), 5 * opt.misalignment_sigma_rad);
  }
  for (const size_t k : {size_t{0}, size_t{4000}, size_t{9000}}) {
    const auto ideal = ImuSimulator::ideal(tr.evaluate(imu[k].t.sec()));
    EXPECT_LT((imu[k].acc_m_s2 - Ta * ideal.acc_m_s2).norm(), 1e-12);
    EXPECT_LT((imu[k].gyro_rad_s - Tg * ideal.gyro_rad_s).norm(), 1e-12);
  }
  // Noise and biases drawn as without axis errors (their own streams).
  ImuNoiseOptions noisy;
  ImuNoiseOptions noisy_axes = noisy;
  noisy_axes.scale_sigma = 0.01;
  ImuSimulator plain(noisy, 7), axes(noisy_axes, 7);
  plain.simulate(tr, 10.0);
  axes.simulate(tr, 10.0);
  EXPECT_EQ(plain.initialAccBias(), axes.initialAccBias());
  EXPECT_EQ(plain.finalGyroBias(), axes.finalGyroBias());
  EXPECT_TRUE(plain.accAxes().isIdentity());
}

// Rotor vibration (issue 36 item 7): an airborne rotorcraft's IMU shakes, on the pad it does not,
// a hand-carried rig never does; the tones alias far from 0 Hz, so they average out over a
// fraction of a second and integrate to nothing a filter would notice.
TEST(SimImuSimulator, RotorVibrationShakesAnAirborneImuOnlyAndAveragesOut) {
  const SpiralTrajectory tr(TrajectoryOptions::randomized(1));
  ImuNoiseOptions opt = ImuNoiseOptions::noiseless();
  opt.vibration_acc_m_s2 = 0.6;
  opt.vibration_gyro_rad_s = 0.03;
  ImuSimulator sim(opt, 3);
  const auto imu = sim.simulate(tr, tr.duration());
  const auto error = [&](size_t k) {
    const auto ideal = ImuSimulator::ideal(tr.evaluate(imu[k].t.sec()));
    return std::pair<Eigen::Vector3d, Eigen::Vector3d>(imu[k].acc_m_s2 - ideal.acc_m_s2,
                                                       imu[k].gyro_rad_s - ideal.gyro_rad_s);
  };
  ASSERT_GT(tr.takeoffTime(), 1.0);
  for (size_t k = 0; imu[k].t.sec() < tr.takeoffTime() - 0.1; ++k) {  // on the pad: motors off
    EXPECT_LT(error(k).first.norm(), 1e-12);
    EXPECT_LT(error(k).second.norm(), 1e-12);
  }
  // In the air, 40-45 s: per-axis RMS A_i/√2 with A_i in [0.5, 1.5] × the amplitude scale, and a
  // mean over every 0.5 s window near zero (the tones alias to 30-90 Hz).
  const size_t k0 = 40 * 200, k1 = 45 * 200;
  Eigen::Vector3d ss_acc = Eigen::Vector3d::Zero(), ss_gyro = Eigen::Vector3d::Zero();
  for (size_t w = k0; w < k1; w += 100) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (size_t k = w; k < w + 100; ++k) {
      const auto [ea, eg] = error(k);
      ss_acc += ea.cwiseAbs2();
      ss_gyro += eg.cwiseAbs2();
      mean += ea / 100.0;
    }
    EXPECT_LT(mean.cwiseAbs().maxCoeff(), 0.05) << "window at " << imu[w].t.sec() << " s";
  }
  const Eigen::Vector3d rms_acc = (ss_acc / static_cast<double>(k1 - k0)).cwiseSqrt();
  const Eigen::Vector3d rms_gyro = (ss_gyro / static_cast<double>(k1 - k0)).cwiseSqrt();
  EXPECT_GT(rms_acc.minCoeff(), 0.5 * 0.6 / std::sqrt(2.0) * 0.8);
  EXPECT_LT(rms_acc.maxCoeff(), 1.5 * 0.6 / std::sqrt(2.0) * 1.2);
  EXPECT_GT(rms_gyro.minCoeff(), 0.5 * 0.03 / std::sqrt(2.0) * 0.8);
  EXPECT_LT(rms_gyro.maxCoeff(), 1.5 * 0.03 / std::sqrt(2.0) * 1.2);
  // Integrated over 10 s of flight: a tone's integral leaves a velocity offset of at most
  // A/(2π f_alias) (its starting phase), millimetres per second; far below what the IMU's own bias
  // does (the default σ 0.05 m/s² alone: 0.5 m/s and 2.5 m in 10 s), so a tenth of that bounds it.
  const size_t j0 = 60 * 200, j1 = 70 * 200;
  const NavState x = integrate(imu, j0, j1, trueState(tr.evaluate(imu[j0].t.sec())));
  const auto truth = tr.evaluate(imu[j1].t.sec());
  EXPECT_LT((x.p - truth.p_IinG).norm(), 0.25);
  EXPECT_LT((x.v - truth.v_IinG).norm(), 0.05);
  EXPECT_LT(toQuat(x.q).angularDistance(truth.q_ItoG), 1e-3);
}

TEST(SimImuSimulator, AHandCarriedRigDoesNotVibrateAndVibrationLeavesTheOtherDrawsAsTheyWere) {
  const WalkTrajectory walk(Hall::paper(), 30.0, 2);
  ImuNoiseOptions opt = ImuNoiseOptions::noiseless();
  opt.vibration_acc_m_s2 = 0.6;
  opt.vibration_gyro_rad_s = 0.03;
  ImuSimulator sim(opt, 3);
  const auto imu = sim.simulate(walk, 10.0);
  for (size_t k = 0; k < imu.size(); k += 50)
    EXPECT_LT((imu[k].acc_m_s2 - ImuSimulator::ideal(walk.evaluate(imu[k].t.sec())).acc_m_s2).norm(), 1e-12);
  // With the default noise: the same biases and the same readings on the pad, with or without.
  const SpiralTrajectory tr(TrajectoryOptions::randomized(1));
  ImuNoiseOptions still = ImuNoiseOptions{};
  still.vibration_acc_m_s2 = still.vibration_gyro_rad_s = 0.0;
  ImuSimulator a(ImuNoiseOptions{}, 7), b(still, 7);
  const auto sa = a.simulate(tr, 10.0), sb = b.simulate(tr, 10.0);
  EXPECT_EQ(a.finalAccBias(), b.finalAccBias());
  EXPECT_EQ(sa[10].acc_m_s2, sb[10].acc_m_s2);
  EXPECT_NE(sa.back().acc_m_s2, sb.back().acc_m_s2);  // airborne at 10 s
}
