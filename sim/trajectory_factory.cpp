#include "sim/trajectory_factory.h"

#include <stdexcept>

#include "sim/figure8_trajectory.h"
#include "sim/helix_trajectory.h"
#include "sim/hover_trajectory.h"
#include "sim/lawnmower_trajectory.h"
#include "sim/spiral_trajectory.h"
#include "sim/walk_trajectory.h"

namespace meshnav::sim {

namespace {
constexpr double kNominalDuration_s = 140.0;  ///< the paper's sequence length at duration_scale 1
}  // namespace

std::unique_ptr<Trajectory> makeTrajectory(const SimulationOptions& o) {
  const Hall hall = o.flight_region.value_or(o.hall());
  const double duration_s = o.duration_s ? *o.duration_s : kNominalDuration_s * o.duration_scale;
  switch (o.trajectory_kind) {
    case TrajectoryKind::Spiral: {
      if (o.trajectory) return std::make_unique<SpiralTrajectory>(*o.trajectory);
      const double scale = o.duration_s ? *o.duration_s / kNominalDuration_s : o.duration_scale;
      TrajectoryOptions spiral = TrajectoryOptions::randomized(o.seed, scale);
      if (o.hall_size_m || o.flight_region) spiral = spiral.fittedTo(hall);
      return std::make_unique<SpiralTrajectory>(spiral);
    }
    case TrajectoryKind::Figure8: return std::make_unique<Figure8Trajectory>(hall, duration_s, o.seed);
    case TrajectoryKind::Lawnmower: return std::make_unique<LawnmowerTrajectory>(hall, duration_s, o.seed);
    case TrajectoryKind::Helix: return std::make_unique<HelixTrajectory>(hall, duration_s, o.seed);
    case TrajectoryKind::Hover: return std::make_unique<HoverTrajectory>(hall, duration_s, o.seed);
    case TrajectoryKind::Walk: return std::make_unique<WalkTrajectory>(hall, duration_s, o.seed);
  }
  throw std::invalid_argument("makeTrajectory: unknown trajectory kind");
}

}  // namespace meshnav::sim
