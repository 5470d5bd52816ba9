#include "sim/smooth_progress.h"

#include <stdexcept>

namespace meshnav::sim {

SmoothProgress::SmoothProgress(double t_start_s, double ramp_s, double t_end_s)
    : t_start_s_(t_start_s), ramp_s_(ramp_s), t_end_s_(t_end_s) {
  if (!(ramp_s_ > 0.0) || !(t_end_s_ - t_start_s_ >= 2.0 * ramp_s_))
    throw std::invalid_argument("SmoothProgress: needs t_end - t_start >= 2 ramp > 0");
}

PositionJet SmoothProgress::progress(const PositionJet& t) const {
  const double t_b = t_end_s_ - ramp_s_;
  const PositionJet ramp = smoothStepIntegral((t - t_start_s_) / ramp_s_) - smoothStepIntegral((t - t_b) / ramp_s_);
  return ramp * (ramp_s_ / (t_b - t_start_s_));
}

PositionJet SmoothProgress::envelope(const PositionJet& t) const {
  const double t_b = t_end_s_ - ramp_s_;
  return smoothStep((t - t_start_s_) / ramp_s_) - smoothStep((t - t_b) / ramp_s_);
}

}  // namespace meshnav::sim
