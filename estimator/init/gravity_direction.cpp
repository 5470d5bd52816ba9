/// @file gravity_direction.cpp
/// @brief GravityDirection: the sign of gravity along z of the anchors' frame (gravity_direction.h).

#include "estimator/init/gravity_direction.h"

#include <algorithm>

#include <spdlog/spdlog.h>

namespace meshnav::estimator {

namespace {

std::string costsText(const MotionAligner::GravityCheck& c) {
  return fmt::format("cost {:.1f} with gravity along -z, {:.1f} along +z, margin {:.1f}, {} ranges", c.cost_z_up,
                     c.cost_z_down, c.margin, c.n_ranges);
}

}  // namespace

GravityDirection::GravityDirection(double first_s, double window_s, double early_nis_ratio, Diagnostics& diag)
    : first_s_(first_s), window_s_(window_s), early_nis_ratio_(early_nis_ratio), diag_(diag) {}

void GravityDirection::scheduleNext(Timestamp t) {
  // The data since the initialization doubles: first_s, then steps of 2 first_s, 4 first_s, …
  // capped at the window (the aligner fits no more than a window).
  step_s_ = std::min(step_s_ > 0.0 ? 2.0 * step_s_ : first_s_, window_s_);
  check_at_ = t + Duration::fromSec(step_s_);
}

void GravityDirection::reset() {
  sign_ = -1.0;
  check_at_.reset();
  checks_ = 0;
  step_s_ = 0.0;
  early_due_ = early_checked_ = false;
  reinit_pending_ = false;
  last_reinit_try_.reset();
}

void GravityDirection::onInitialized(Timestamp t, int decided_sign) {
  if (decided_sign != 0 && checks_ == 0) {
    check_at_.reset();
    checks_ = kMaxChecks;  // decided: nothing more to compare
    if (decided_sign > 0) {
      diag_.count("anchor_frame_z_down");
      sign_ = 1.0;
    }
    return;
  }
  if (checks_ == 0 && !check_at_) {
    step_s_ = 0.0;
    scheduleNext(t);  // first_s after it
  }
}

void GravityDirection::noteRangeNisRatio(double ratio) {
  if (early_nis_ratio_ > 0.0 && ratio >= early_nis_ratio_ && checks_ == 0 && check_at_ && !early_checked_)
    early_due_ = true;
}

void GravityDirection::onImu(Timestamp t, Context& c) {
  if (early_due_) earlyCheck(t, c);
  if (check_at_ && t >= *check_at_) scheduledCheck(t, c);
  if (reinit_pending_ && (!last_reinit_try_ || (t - *last_reinit_try_).sec() >= kFlipRetry_s)) tryReinitialize(t, c);
}

void GravityDirection::scheduledCheck(Timestamp t, Context& c) {
  check_at_.reset();
  ++checks_;
  const auto check = c.compareGravitySigns();
  if (!check) {
    spdlog::info("estimator: gravity direction not checked at t={}: {}", formatSeconds(t), c.whyNot());
    if (checks_ < kMaxChecks) scheduleNext(t);
    return;
  }
  if (check->zDown()) {
    takePlusZ(t, *check, c);
    return;
  }
  spdlog::info("estimator: gravity direction at t={}: {} ({})", formatSeconds(t),
               check->zUp() ? "along -z of G as assumed" : "undecided", costsText(*check));
  // Undecided (little motion in the window): again when the data has doubled, at most kMaxChecks times.
  if (!check->zUp() && checks_ < kMaxChecks) scheduleNext(t);
}

void GravityDirection::earlyCheck(Timestamp t, Context& c) {
  early_due_ = false;
  early_checked_ = true;
  // With baro or heights the frame is taken as it is (they measure along −z); the scheduled
  // comparison says so once.
  if (c.hasVerticalSensor()) return;
  diag_.count("gravity_early_check");
  const auto check = c.compareGravitySigns();
  if (!check || !check->zDown()) {
    spdlog::info("estimator: early gravity check at t={} (median range NIS {:.1f}x its expected value): {}; the "
                 "check at t={} still runs",
                 formatSeconds(t), c.rangeNisRatio(),
                 !check ? c.whyNot()
                        : (check->zUp() ? "along -z of G as assumed" : "undecided") + (" (" + costsText(*check) + ")"),
                 formatSeconds(*check_at_));
    return;
  }
  check_at_.reset();
  ++checks_;
  takePlusZ(t, *check, c);
}

void GravityDirection::takePlusZ(Timestamp t, const MotionAligner::GravityCheck& check, Context& c) {
  diag_.count("anchor_frame_z_down");
  if (c.hasVerticalSensor()) {
    spdlog::warn(
        "estimator: at t={} the anchors' frame G fits the IMU upside down ({}), but baro or heights measure along "
        "-z: kept gravity along -z of G; expect poor estimates (docs/real_data.md)",
        formatSeconds(t), costsText(check));
    return;
  }
  spdlog::warn("estimator: at t={} the anchors' frame G fits the IMU upside down ({}): its z axis points down; "
               "gravity is taken along +z of G from now on (docs/real_data.md)",
               formatSeconds(t), costsText(check));
  sign_ = 1.0;
  c.gravityTurned();
  reinit_pending_ = true;
  tryReinitialize(t, c);
}

void GravityDirection::tryReinitialize(Timestamp t, Context& c) {
  last_reinit_try_ = t;
  if (!c.reinitializeWithGravity(t)) {
    diag_.count("gravity_flip_refused");
    return;
  }
  reinit_pending_ = false;
  diag_.count("gravity_flip");
}

}  // namespace meshnav::estimator
