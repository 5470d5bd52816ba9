// The contract of the Trajectory interface (sim/trajectory.h), for every kind of motion: the
// simulated noise-free IMU integrates back to the truth, and the motion stays inside the hall.
#include <gtest/gtest.h>

#include "sim/trajectory_factory.h"
#include "trajectory_checks.h"

using namespace meshnav::sim;
using namespace meshnav::sim::test;

namespace {
class SimTrajectory : public ::testing::TestWithParam<TrajectoryKind> {
 protected:
  std::unique_ptr<Trajectory> make(const Hall& hall, double duration_s, uint64_t seed) const {
    SimulationOptions o;
    o.trajectory_kind = GetParam();
    o.seed = seed;
    if (hall.min_m != Hall::paper().min_m || hall.max_m != Hall::paper().max_m) o.hall_size_m = hall.size();
    o.duration_s = duration_s;
    return makeTrajectory(o);
  }
};
}  // namespace

TEST_P(SimTrajectory, NoiseFreeDeadReckoningFollowsTheTruthOverTheWholeMotion) {
  for (uint64_t seed : {1u, 2u}) {
    const auto tr = make(Hall::paper(), 140.0, seed);
    const DeadReckoningError e = deadReckon(*tr);
    // Analytic derivatives: far below a millimetre after 140 s (RK4 at 200 Hz, exact inputs).
    EXPECT_LT(e.position_m, 1e-4) << "seed " << seed;
    EXPECT_LT(e.velocity_m_s, 1e-5) << "seed " << seed;
    EXPECT_LT(e.attitude_rad, 1e-7) << "seed " << seed;
  }
}

TEST_P(SimTrajectory, StaysInsideEveryHallWithAMargin) {
  for (const Hall& hall : testHalls())
    for (uint64_t seed : {1u, 2u, 3u})
      for (double duration : {60.0, 140.0}) {
        const auto tr = make(hall, duration, seed);
        const HallClearance c = clearance(*tr, hall);
        EXPECT_GT(c.walls_m, 0.3) << hall.toString() << " seed " << seed << " " << duration << " s";
        EXPECT_GT(c.floor_m, 0.05) << hall.toString() << " seed " << seed << " " << duration << " s";
        EXPECT_GT(c.ceiling_m, 0.3) << hall.toString() << " seed " << seed << " " << duration << " s";
      }
}

TEST_P(SimTrajectory, LandedPhasesAreConsistent) {
  const auto tr = make(Hall::ofSize({8.0, 8.0, 4.0}), 90.0, 3);
  const bool pad_flight = GetParam() != TrajectoryKind::Hover && GetParam() != TrajectoryKind::Walk;
  EXPECT_EQ(tr->hasLandedPhase(), pad_flight);
  EXPECT_EQ(tr->isLanded(0.0), pad_flight);
  EXPECT_FALSE(tr->isLanded(0.5 * tr->duration()));
  EXPECT_EQ(tr->hasBarometer(), GetParam() != TrajectoryKind::Walk);
  if (pad_flight) {
    EXPECT_LT(tr->evaluate(0.0).v_IinG.norm(), 1e-12);
    EXPECT_LT((tr->evaluate(0.0).p_IinG - tr->evaluate(tr->duration()).p_IinG).norm(), 1e-9);  // lands at the start
    EXPECT_GT(tr->takeoffTime(), 0.0);
    EXPECT_LT(tr->touchdownTime(), tr->duration());
  }
}

INSTANTIATE_TEST_SUITE_P(EveryKind, SimTrajectory,
                         ::testing::Values(TrajectoryKind::Spiral, TrajectoryKind::Figure8, TrajectoryKind::Lawnmower,
                                           TrajectoryKind::Helix, TrajectoryKind::Hover, TrajectoryKind::Walk),
                         [](const auto& info) { return toString(info.param); });
