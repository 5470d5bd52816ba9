/// Every measurement model's Jacobian blocks against numerical differentiation over the error state.
#include <gtest/gtest.h>

#include "estimator/baro/baro_model.h"
#include "estimator/uwb/range_model.h"
#include "estimator/zupt/zupt_model.h"
#include "test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;
using namespace meshnav::estimator::test;

namespace {

UwbNetwork network(double clock_offset_s = 0.0) {
  SystemSetup s;
  s.rel_tag_positions = {{100, {-0.19, 0.105, -0.07}}, {105, {0.05, -0.105, -0.07}}};
  s.abs_anchor_positions = {{101, {-1.308, -4.140, 0.66}}, {106, {-1.772, 0.943, 3.256}}, {107, {-2.021, 1.814, 1.732}}};
  s.abs_anchor_sigmas_m = {{106, 0.1}, {107, 0.1}};
  s.pair_biases.push_back({100, 106, 0.2, 1.02, 0.1, 0.0, 0.0});
  s.pair_biases.push_back({106, 107, -0.1, 0.98, 0.1, 0.0, 0.0});
  s.uwb_clock.offset_s = clock_offset_s;
  return UwbNetwork(s, 0.15);
}

/// How the UWB clock enters: not at all, as setup's constant delay, or as a state (id 4).
enum class Clock { None, Constant, State };

void expectRangeJacobian(SensorId a, SensorId b, std::initializer_list<SensorId> expected_blocks,
                         Clock clock = Clock::None) {
  const UwbNetwork net = network(clock == Clock::Constant ? 0.035 : 0.0);
  for (unsigned seed = 1; seed <= 5; ++seed) {
    NominalState x = randomState(seed);
    if (clock == Clock::State) x.values<ClockOffsetKind>()[4] = -0.04;
    StateLayout layout = layoutOf(x);
    if (clock == Clock::State) layout.add(4, kindOf<ClockOffsetKind>);
    RangeMeasurement z{Timestamp{}, a, b, 5.0, 0.0};
    z.omega_IinI_rad_s = Eigen::Vector3d(0.8, -1.5, 2.2);  // a tag on a lever arm: ω enters with the delay
    Linearization lin;
    ASSERT_EQ(RangeModel::linearize(z, x, net, &lin), RangeModel::Status::Ok);
    ASSERT_EQ(lin.blocks.size(), expected_blocks.size());
    for (SensorId id : expected_blocks) EXPECT_NE(lin.find(id), nullptr) << "block " << id;
    // r = z − h ⇒ H = ∂h/∂δx = −∂r/∂δx; compare against the prediction directly.
    const auto h = [&](const NominalState& s) {
      return Eigen::VectorXd::Constant(1, RangeModel::predict(z, s, net)->first);
    };
    const Eigen::MatrixXd Hn = numericalJacobian(x, layout, h);
    EXPECT_TRUE(stack(lin, layout).isApprox(Hn, 1e-6)) << "analytic\n" << stack(lin, layout) << "\nnumeric\n" << Hn;
    EXPECT_NEAR(lin.residual(0), z.z_m - h(x)(0), 1e-12);
  }
}

}  // namespace

TEST(MeasurementJacobians, RangeTagToExactAnchor) { expectRangeJacobian(100, 101, {1}); }
TEST(MeasurementJacobians, RangeExactAnchorToTag) { expectRangeJacobian(101, 105, {1}); }
TEST(MeasurementJacobians, RangeTagToEstimatedAnchorWithBias) { expectRangeJacobian(106, 100, {1, 106}); }
TEST(MeasurementJacobians, RangeAnchorToAnchor) { expectRangeJacobian(106, 107, {106, 107}); }
TEST(MeasurementJacobians, RangeEstimatedToExactAnchor) { expectRangeJacobian(101, 107, {107}); }
TEST(MeasurementJacobians, RangeWithAConstantClockDelay) { expectRangeJacobian(100, 101, {1}, Clock::Constant); }
TEST(MeasurementJacobians, RangeWithTheClockDelayAsAState) { expectRangeJacobian(100, 101, {1, 4}, Clock::State); }
TEST(MeasurementJacobians, RangeBetweenAnchorsIgnoresTheClock) { expectRangeJacobian(106, 107, {106, 107}, Clock::State); }

/// The delay moves the tag back along its path: a tag 10 m from an anchor, flying away from it at
/// 2 m/s, with its ranges stamped 0.05 s late, was 0.1 m nearer when the range was measured.
TEST(MeasurementJacobians, TheClockDelayTakesTheTagWhereItWas) {
  SystemSetup s;
  s.rel_tag_positions = {{100, {0, 0, 0}}};
  s.abs_anchor_positions = {{101, {0, 0, 0}}};
  s.uwb_clock.offset_s = 0.05;
  NominalState x;
  x.imu_id = 1;
  x.imu.p_IinG = Eigen::Vector3d(10, 0, 0);
  x.imu.v_IinG = Eigen::Vector3d(2, 0, 0);
  const RangeMeasurement z{Timestamp{}, 100, 101, 9.9, 0.0};
  EXPECT_NEAR(RangeModel::predict(z, x, UwbNetwork(s, 0.1))->first, 9.9, 1e-12);
  s.uwb_clock.offset_s = 0.0;
  EXPECT_NEAR(RangeModel::predict(z, x, UwbNetwork(s, 0.1))->first, 10.0, 1e-12);
  // As a state: ∂h/∂δ_u = uᵀ v_T = −2 m/s (u points from the tag to the anchor).
  x.values<ClockOffsetKind>()[4] = 0.05;
  Linearization lin;
  ASSERT_EQ(RangeModel::linearize(z, x, UwbNetwork(s, 0.1), &lin), RangeModel::Status::Ok);
  ASSERT_NE(lin.find(4), nullptr);
  EXPECT_NEAR(lin.find(4)->H(0, 0), -2.0, 1e-12);
  EXPECT_NEAR(lin.residual(0), 0.0, 1e-12);
}

TEST(MeasurementJacobians, RangeClassification) {
  const UwbNetwork net = network();
  const NominalState x = randomState(1);
  Linearization lin;
  EXPECT_EQ(RangeModel::linearize({Timestamp{}, 100, 999, 3.0, 0.0}, x, net, &lin), RangeModel::Status::UnknownId);
  EXPECT_EQ(RangeModel::linearize({Timestamp{}, 100, 105, 3.0, 0.0}, x, net, &lin), RangeModel::Status::TagTag);
  SystemSetup s;
  s.abs_anchor_positions = {{101, {0, 0, 0}}, {102, {1, 0, 0}}};
  EXPECT_EQ(RangeModel::linearize({Timestamp{}, 101, 102, 1.0, 0.0}, x, UwbNetwork(s, 0.1), &lin),
            RangeModel::Status::NoState);
  EXPECT_EQ(RangeModel::classify({Timestamp{}, 100, 999, 3.0, 0.0}, x, net), RangeModel::Status::UnknownId);
}

TEST(MeasurementJacobians, RangeNoiseFollowsPairThenSetupThenRThenConfig) {
  SystemSetup s;
  s.rel_tag_positions = {{100, {0, 0, 0}}};
  s.abs_anchor_positions = {{101, {1, 0, 0}}, {102, {0, 1, 0}}};
  s.pair_biases.push_back({100, 101, 0.0, 1.0, 0.3, 0.0, 0.0});
  UwbNetwork net(s, 0.15);
  EXPECT_DOUBLE_EQ(net.rangeSigma(101, 100, 0.04), 0.3);  // pair σ
  EXPECT_DOUBLE_EQ(net.rangeSigma(100, 102, 0.04), 0.2);  // √R
  EXPECT_DOUBLE_EQ(net.rangeSigma(100, 102, 0.0), 0.15);  // config
  s.noise.sigma_range_m = 0.12;
  EXPECT_DOUBLE_EQ(UwbNetwork(s, 0.15).rangeSigma(100, 102, 0.04), 0.12);  // setup σ
}

TEST(MeasurementJacobians, Baro) {
  const BaroModel model(Eigen::Vector3d(0.03, -0.02, 0.05));
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const NominalState x = randomState(seed);
    const StateLayout layout = layoutOf(x);
    BaroMeasurement z{Timestamp{}, 2, 4.0, 0.2};
    const Linearization lin = model.linearize(z, x);
    const auto h = [&](const NominalState& s) { return Eigen::VectorXd::Constant(1, model.predict(z, s)); };
    EXPECT_TRUE(stack(lin, layout).isApprox(numericalJacobian(x, layout, h), 1e-6));
    EXPECT_NEAR(lin.residual(0), 4.0 - model.predict(z, x), 1e-12);
    EXPECT_NEAR(lin.R(0, 0), 0.04, 1e-15);
  }
}

TEST(MeasurementJacobians, Zupt) {
  const ZuptModel model(Eigen::Vector3d(0, 0, -9.81));
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const NominalState x = randomState(seed);
    const StateLayout layout = layoutOf(x);
    ZuptMeasurement z;
    z.acc_m_s2 = Eigen::Vector3d(0.1, -0.2, 9.7);
    z.gyro_rad_s = Eigen::Vector3d(0.01, 0.02, -0.01);
    const Linearization lin = model.linearize(z, x);
    const auto h = [&](const NominalState& s) { return Eigen::VectorXd(model.predict(z, s)); };
    const Eigen::MatrixXd Hn = numericalJacobian(x, layout, h);
    EXPECT_TRUE(stack(lin, layout).isApprox(Hn, 1e-6)) << stack(lin, layout) << "\n\n" << Hn;
    EXPECT_TRUE(lin.residual.isApprox(-h(x)));
    // The paper's form: ∂a/∂δθ = −[R̂ᵀ g_up]×.
    const Eigen::Vector3d g_up(0, 0, 9.81);
    const Eigen::Matrix3d H_theta = lin.blocks[0].H.block<3, 3>(0, ImuErr::kTheta);
    EXPECT_TRUE(H_theta.isApprox(-so3::skew(x.imu.q_ItoG.conjugate() * g_up)));
  }
}
