#include <gtest/gtest.h>

#include "sim/spiral_trajectory.h"
#include "sim/trajectory_factory.h"

using namespace meshnav::sim;

TEST(SimTrajectoryFactory, DefaultOptionsGiveThePapersSpiralUnchanged) {
  for (uint64_t seed : {1u, 5u, 12u}) {
    SimulationOptions o;
    o.seed = seed;
    const auto tr = makeTrajectory(o);
    const SpiralTrajectory reference(TrajectoryOptions::randomized(seed));
    EXPECT_EQ(tr->kind(), "spiral");
    EXPECT_EQ(tr->duration(), reference.duration());
    for (double t = 0.0; t < reference.duration(); t += 7.3) {
      const auto a = tr->evaluate(t), b = reference.evaluate(t);
      EXPECT_EQ(a.p_IinG, b.p_IinG) << "t " << t;  // bit-identical
      EXPECT_EQ(a.w_IinI, b.w_IinI) << "t " << t;
      EXPECT_EQ(a.a_IinG, b.a_IinG) << "t " << t;
    }
  }
}

TEST(SimTrajectoryFactory, EveryKindWithHallAndDuration) {
  for (TrajectoryKind kind : {TrajectoryKind::Spiral, TrajectoryKind::Figure8, TrajectoryKind::Lawnmower,
                              TrajectoryKind::Helix, TrajectoryKind::Hover, TrajectoryKind::Walk}) {
    SimulationOptions o;
    o.trajectory_kind = kind;
    o.hall_size_m = Eigen::Vector3d(8.0, 7.0, 4.0);
    o.duration_s = 75.0;
    const auto tr = makeTrajectory(o);
    EXPECT_EQ(tr->kind(), toString(kind));
    EXPECT_NEAR(tr->duration(), 75.0, kind == TrajectoryKind::Spiral ? 3.0 : 1e-9) << toString(kind);
    EXPECT_EQ(parseTrajectoryKind(toString(kind)), kind);
    const Hall hall = o.hall();
    for (double t = 0.0; t <= tr->duration(); t += 0.25)
      ASSERT_TRUE(hall.contains(tr->evaluate(t).p_IinG, 0.3, 0.05, 0.3)) << toString(kind) << " t " << t;
  }
  EXPECT_FALSE(parseTrajectoryKind("foo").has_value());
}

TEST(SimTrajectoryFactory, SpiralFittedIntoSmallAndLargeHalls) {
  for (const Eigen::Vector3d& size : {Eigen::Vector3d(6, 6, 3), Eigen::Vector3d(12, 12, 8), Eigen::Vector3d(12, 6, 5)})
    for (uint64_t seed : {1u, 2u, 3u, 4u}) {
      const Hall hall = Hall::ofSize(size);
      const SpiralTrajectory tr(TrajectoryOptions::randomized(seed).fittedTo(hall));
      for (double t = 0.0; t <= tr.duration(); t += 0.25)
        ASSERT_TRUE(hall.contains(tr.evaluate(t).p_IinG, 0.3, 0.05, 0.3)) << size.transpose() << " seed " << seed << " t " << t;
    }
}
