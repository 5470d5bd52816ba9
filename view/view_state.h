#pragma once
/// @file view_state.h
/// @brief What the live view shows, gathered from the project's plain messages (no LCM): the
/// estimated path with the position covariance, the truth when it is on the bus, the anchors with
/// their calibration state and uncertainty, the health, per-anchor range residuals and every
/// status channel; written as one JSON snapshot that a page polls incrementally (docs/view.md,
/// "The state endpoint").
///
/// Times in the JSON are seconds since the first message the view got (`t0_utime` gives that
/// instant in µs of the data's clock), so that Unix-epoch stamps of live data keep their precision.
///
/// Path: a POSE joins the path when it is at least `path_min_step_m` from the last kept point or
/// `path_max_gap_s` after it (the current pose is always sent in full); a full path is thinned
/// (Track::Overflow::Thin). Residuals are a window of the newest rows (Track::Overflow::DropOldest).
///
/// Anchors: ANCHORS gives the positions the estimator holds (zero covariance: a known anchor,
/// "known"; otherwise an estimated one); CALIB_STATUS gives the calibrator's state ("collecting",
/// "calibrated", "refused") and reason; setup.yaml, when given, the known anchors before the first
/// ANCHORS. An anchor only heard of in RANGE or CALIB_STATUS is listed without a position.
///
/// A new status channel needs one call: onStatusFields(channel, t, name/value lines), shown by the
/// page as a table under the channel's name (EstimatorStatus, CalibStatus and MissionStatus go
/// through it as well).

#include <deque>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "common/diagnostics.h"
#include "common/messages.h"
#include "common/setup.h"
#include "common/types.h"
#include "view/covariance_ellipse.h"
#include "view/range_residuals.h"
#include "view/track.h"

namespace meshnav::view {

struct ViewStateOptions {
  double path_min_step_m = 0.02;     ///< a POSE this far from the last path point joins the path [m]
  double path_max_gap_s = 0.5;       ///< …or this long after it [s of data time]
  size_t path_capacity = 20000;      ///< path points kept before thinning
  size_t residual_capacity = 20000;  ///< residual rows kept (the newest)
  size_t residual_window = 50;       ///< residuals per anchor behind the mean and RMS in the table
  double ellipse_scale = kChi2Scale95;  ///< k of the x–y ellipses (95 %)
};

/// Where the data comes from, shown by the page (set by the server).
struct ViewSource {
  std::string mode = "live";  ///< "live" or "log"
  std::string description;    ///< the LCM URL, or the log file
  double speed = 1.0;         ///< playback speed factor (log)
  double progress = 0.0;      ///< fraction of the log played [0, 1] (log)
  bool done = false;          ///< the log has been played to its end
};

/// What a page already holds: the epoch and row count of each track (-1: nothing).
struct ViewCursor {
  int64_t path_epoch = -1;
  size_t path_rows = 0;
  int64_t truth_epoch = -1;
  size_t truth_rows = 0;
  int64_t residual_epoch = -1;
  size_t residual_rows = 0;
};

class ViewState {
 public:
  explicit ViewState(ViewStateOptions options = {});

  /// Tag lever arms (for the residuals) and known anchors from setup.yaml.
  void setSetup(const SystemSetup& setup);

  void onPose(const PoseEstimate& p);
  void onGroundTruth(const PoseSample& p);
  void onAnchors(const std::vector<AnchorEstimate>& anchors);
  void onRange(const RangeSample& r);
  void onEstimatorStatus(const EstimatorStatus& s);
  void onCalibStatus(const CalibStatus& s);
  void onMissionStatus(const MissionStatus& s);
  /// A status channel as name/value lines, replacing what `channel` showed before.
  void onStatusFields(const std::string& channel, Timestamp t, std::vector<std::pair<std::string, std::string>> fields);

  void setSource(const ViewSource& source) { source_ = source; }
  /// Counters of the transport (malformed messages per channel …), shown beside the view's own.
  void setTransportCounters(std::map<std::string, int64_t> counters) { transport_counters_ = std::move(counters); }

  /// The snapshot for a page holding `cursor` (docs/view.md, "The state endpoint").
  std::string json(const ViewCursor& cursor) const;

  /// Messages taken so far (every on*() call).
  int64_t updates() const { return updates_; }
  bool hasPose() const { return pose_.has_value(); }
  const Track& path() const { return path_; }
  const Track& truth() const { return truth_; }
  const Track& residuals() const { return residuals_; }
  /// The view's own counters (residuals that could not be formed, messages out of order).
  std::map<std::string, int64_t> counters() const;

  /// One anchor as shown.
  struct Anchor {
    SensorId id = 0;
    std::optional<Eigen::Vector3d> p_AinG;
    Eigen::Matrix3d cov_m2 = Eigen::Matrix3d::Zero();
    bool in_estimator = false;  ///< in the last ANCHORS
    bool from_setup = false;    ///< a known anchor of setup.yaml
    std::string calib_state;    ///< CALIB_STATUS state, "" when the calibrator has not named it
    std::string calib_reason;
    int64_t n_ranges = 0;       ///< ranges seen on the bus with this anchor
    /// Newest residuals (at most residual_window) [m].
    std::deque<double> recent_residuals_m;
    double last_residual_m = 0.0;
    int64_t n_residuals = 0;
    /// "known", "estimated", "calibrated", "collecting", "refused" or "unknown" (no position).
    std::string state() const;
  };
  const std::map<SensorId, Anchor>& anchors() const { return anchors_; }

 private:
  /// Seconds since t0 (set by the first message).
  double rel(Timestamp t);
  double relConst(Timestamp t) const { return t0_ ? (t - *t0_).sec() : 0.0; }
  void onResidual(const RangeResidual& r);
  /// True when a point (t [s since t0], p) joins `track` (rows t, x, y, z, …): the first one, or
  /// path_min_step_m from its last point, or path_max_gap_s after it.
  bool joins(const Track& track, double t, const Eigen::Vector3d& p) const;

  ViewStateOptions options_;
  std::optional<Timestamp> t0_;
  std::optional<Timestamp> t_latest_;
  std::optional<PoseEstimate> pose_;
  std::optional<PoseSample> truth_pose_;
  Track path_;       ///< t, x, y, z, the x–y ellipse a, b, angle (ellipse_scale), σz
  Track truth_;      ///< t, x, y, z
  Track residuals_;  ///< t, anchor id, residual
  std::map<SensorId, Anchor> anchors_;
  std::optional<EstimatorStatus> estimator_status_;
  /// channel → (t, lines), in the order first seen
  std::vector<std::pair<std::string, std::pair<Timestamp, std::vector<std::pair<std::string, std::string>>>>> statuses_;
  RangeResiduals residual_maker_;
  Diagnostics diag_;
  std::map<std::string, int64_t> transport_counters_;
  ViewSource source_;
  int64_t updates_ = 0;
  int64_t n_poses_ = 0;
  int64_t n_truth_ = 0;
};

}  // namespace meshnav::view
