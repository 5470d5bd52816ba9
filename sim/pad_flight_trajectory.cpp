#include "sim/pad_flight_trajectory.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace meshnav::sim {

PadFlightTiming PadFlightTiming::forDuration(double T) {
  if (!(T >= 30.0)) throw std::invalid_argument("PadFlightTiming: duration must be >= 30 s");
  PadFlightTiming o;
  o.duration_s = T;
  o.takeoff_start_s = 0.035 * T;
  o.takeoff_duration_s = std::max(3.0, 0.045 * T);
  o.pattern_start_s = o.takeoff_start_s + o.takeoff_duration_s + 0.007 * T;
  o.pattern_ramp_s = std::max(2.0, 0.04 * T);
  o.landing_duration_s = std::max(4.0, 0.07 * T);
  o.landing_start_s = T - 0.035 * T - o.landing_duration_s;
  o.pattern_end_s = o.landing_start_s - 0.007 * T;
  o.validate();
  return o;
}

void PadFlightTiming::validate() const {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("PadFlightTiming: ") + what);
  };
  require(takeoff_start_s >= 0.0, "takeoff_start_s must be >= 0");
  require(takeoff_duration_s > 0.0 && landing_duration_s > 0.0, "take-off and landing durations must be > 0");
  require(pattern_start_s >= takeoff_start_s + takeoff_duration_s, "the pattern must start after the take-off");
  require(pattern_ramp_s > 0.0 && pattern_end_s - pattern_start_s >= 2.0 * pattern_ramp_s,
          "pattern_end_s - pattern_start_s must be >= 2 pattern_ramp_s > 0");
  require(landing_start_s >= pattern_end_s, "landing_start_s must be >= pattern_end_s");
  require(duration_s >= landing_start_s + landing_duration_s, "duration_s must cover the landing");
}

std::string PadFlightTiming::toString() const {
  std::ostringstream s;
  s << "take-off " << takeoff_start_s << " s (+" << takeoff_duration_s << " s), pattern " << pattern_start_s << "-"
    << pattern_end_s << " s (ramp " << pattern_ramp_s << " s), landing " << landing_start_s << " s (+"
    << landing_duration_s << " s), end " << duration_s << " s";
  return s.str();
}

PadFlightTrajectory::PadFlightTrajectory(const PadFlightTiming& timing)
    : timing_(timing), pattern_(timing.pattern_start_s, timing.pattern_ramp_s, timing.pattern_end_s) {
  timing_.validate();
}

PositionJet PadFlightTrajectory::airborne(const PositionJet& t) const {
  return smoothStep((t - timing_.takeoff_start_s) / timing_.takeoff_duration_s) -
         smoothStep((t - timing_.landing_start_s) / timing_.landing_duration_s);
}

}  // namespace meshnav::sim
