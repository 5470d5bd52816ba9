/// The registry of instance kinds (estimator/core/instance_kind.h): names, dimensions and indices
/// come from the kinds' traits, and every strategy adds, random-walks, corrects and removes an
/// instance of each scalar kind without naming it (what a new kind relies on).
#include <gtest/gtest.h>

#include <set>
#include <type_traits>

#include "estimator/filter/centralized_ekf.h"
#include "estimator/filter/modular_filter.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

std::vector<std::unique_ptr<FusionStrategy>> allStrategies(const KindRandomWalks& rw) {
  const ImuPropagator prop(9.81, ImuNoiseOptions{});
  std::vector<std::unique_ptr<FusionStrategy>> out;
  out.push_back(std::make_unique<CentralizedEkf>(prop, rw, true));
  out.push_back(std::make_unique<ModularFilter>(ModularFilter::Mode::DP, prop, rw, true));
  out.push_back(std::make_unique<ModularFilter>(ModularFilter::Mode::DAH, prop, rw, true));
  for (auto& f : out) f->reset(1, ImuState{}, ImuMatrix::Identity() * 0.01, Timestamp{});
  return out;
}

}  // namespace

TEST(InstanceKinds, NamesDimensionsAndIndicesComeFromTheTraits) {
  std::set<std::string> names;
  std::set<int> indices;
  int bodies = 0;
  forEachKind([&]<class K>() {
    EXPECT_EQ(kindName(kindOf<K>), K::kName);
    EXPECT_EQ(errorDim(kindOf<K>), K::kDim) << K::kName;
    names.insert(K::kName);
    indices.insert(static_cast<int>(kindOf<K>));
    bodies += K::kBody ? 1 : 0;
  });
  EXPECT_EQ(static_cast<int>(names.size()), kKindCount);
  EXPECT_EQ(static_cast<int>(indices.size()), kKindCount);
  EXPECT_EQ(bodies, 1);
  EXPECT_TRUE(ImuKind::kBody);
  EXPECT_EQ(kindOf<ImuKind>, InstanceKind{0});  // the body's block is first in every layout
  EXPECT_EQ(kindName(InstanceKind{kKindCount}), "?");
}

TEST(InstanceKinds, RandomWalksFromOptionsAreTheKindsOwn) {
  EstimatorOptions o;
  o.baro.bias_rw_m_per_sqrt_s = 0.011;
  o.height.bias_rw_m_per_sqrt_s = 0.007;
  o.uwb.clock_offset_rw_s_per_sqrt_s = 0.0003;
  const KindRandomWalks w = KindRandomWalks::fromOptions(o);
  EXPECT_EQ(w.of(kindOf<ClockOffsetKind>), 0.0003);
  EXPECT_EQ(w.of(kindOf<BaroBiasKind>), 0.011);
  EXPECT_EQ(w.of(kindOf<HeightBiasKind>), 0.007);
  EXPECT_EQ(w.of(kindOf<ImuKind>), 0.0);
  EXPECT_EQ(w.of(kindOf<AnchorKind>), 0.0);
}

TEST(InstanceKinds, EveryStrategyHandlesEachScalarKindThroughTheRegistry) {
  const double sigma = 0.3, var0 = 0.1, dt = 2.0;
  forEachKind([&]<class K>() {
    if constexpr (!K::kBody && std::is_same_v<typename K::Value, double>) {
      for (auto& f : allStrategies(KindRandomWalks{}.set<K>(sigma))) {
        const SensorId id = 50;
        f->template addInstance<K>(id, 0.25, Eigen::MatrixXd::Constant(1, 1, var0));
        ASSERT_EQ(f->layout().at(id).kind, kindOf<K>) << K::kName << " " << f->name();
        EXPECT_EQ(f->state().template values<K>().at(id), 0.25);
        // Its random walk: Σ += σ² Δt.
        f->propagate(Eigen::Vector3d(0, 0, 9.81), Eigen::Vector3d::Zero(), Timestamp::fromSec(dt));
        const double var1 = var0 + sigma * sigma * dt;
        EXPECT_NEAR(f->covariance(id, id)(0, 0), var1, 1e-12) << K::kName << " " << f->name();
        // A direct observation z = b + ν corrects its mean by K r, K = Σ / (Σ + R).
        Linearization lin;
        lin.residual = Eigen::VectorXd::Constant(1, 0.1);
        lin.R = Eigen::MatrixXd::Constant(1, 1, 0.05);
        lin.blocks = {{id, Eigen::MatrixXd::Constant(1, 1, 1.0)}};
        ASSERT_TRUE(f->update(lin, 0.0).accepted);
        EXPECT_NEAR(f->state().template values<K>().at(id), 0.25 + var1 / (var1 + 0.05) * 0.1, 1e-12);
        EXPECT_TRUE(f->removeInstance(id));
        EXPECT_EQ(f->state().template values<K>().count(id), 0u);
        EXPECT_EQ(f->layout().find(id), nullptr);
      }
    }
  });
}

TEST(InstanceKinds, BoxminusUndoesBoxplusForEveryKind) {
  // One instance of each kind of the paper's setup; (x ⊞ δx) ⊟ x = δx block by block.
  NominalState x;
  x.imu.p_IinG = {1.0, -2.0, 3.0};
  x.imu.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()));
  x.values<BaroBiasKind>()[2] = 0.3;
  x.values<HeightBiasKind>()[3] = -0.05;
  x.values<AnchorKind>()[106] = AnchorState{Eigen::Vector3d(-1.772, 0.943, 3.256), BiasState{{100, 101}, Eigen::Vector2d(0.1, -0.2)}};
  x.values<TagBiasKind>()[100] = BiasState{{101, 102, 103}, Eigen::Vector3d(0.05, 0.0, -0.1)};
  StateLayout l;
  l.add(x.imu_id, kindOf<ImuKind>);
  l.add(2, kindOf<BaroBiasKind>);
  l.add(3, kindOf<HeightBiasKind>);
  l.add(106, kindOf<AnchorKind>, 5);
  l.add(100, kindOf<TagBiasKind>, 3);
  ASSERT_EQ(l.dim(), 15 + 1 + 1 + 5 + 3);
  std::srand(7);
  const Eigen::VectorXd dx = Eigen::VectorXd::Random(l.dim()) * 0.1;
  NominalState y = x;
  y.boxplus(l, dx);
  EXPECT_LT((y.boxminus(x, l) - dx).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(x.boxminus(x, l).cwiseAbs().maxCoeff(), 0.0);
  // Values with different numbers of states cannot be compared.
  y.values<TagBiasKind>()[100] = BiasState{{101}, Eigen::VectorXd::Zero(1)};
  EXPECT_THROW(y.boxminus(x, l), std::invalid_argument);
}

TEST(InstanceKinds, AddRefusesACovarianceThatDoesNotFitTheValue) {
  for (auto& f : allStrategies(KindRandomWalks{})) {
    EXPECT_THROW(f->addInstance<BaroBiasKind>(2, 0.0, Eigen::MatrixXd::Identity(2, 2)), std::invalid_argument);
    EXPECT_THROW(f->addInstance<TagBiasKind>(100, BiasState{{101, 102}, Eigen::VectorXd::Zero(1)},
                                             Eigen::MatrixXd::Identity(1, 1)),
                 std::invalid_argument);
    EXPECT_THROW(f->addInstance<AnchorKind>(106, AnchorState{}, Eigen::MatrixXd::Identity(4, 4)),
                 std::invalid_argument);
    EXPECT_EQ(f->layout().blocks().size(), 1u) << f->name();  // nothing added
  }
}
