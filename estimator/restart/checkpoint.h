#pragma once
/// @file checkpoint.h
/// @brief What an estimator needs to resume after a restart without re-initializing: the IMU
/// state with its covariance, every instance a kind keeps across a restart (K::restart,
/// estimator/core/kind_traits.h) and every estimated anchor with its pair biases
/// (docs/robustness.md, "Restarts").
///
/// A restarted estimator process reads the checkpoint its predecessor wrote (`--state-dir`); how
/// it resumes from it is Resume's (estimator/restart/resume.h): a checkpoint at most
/// `init.resume_max_age_s` older than the first IMU sample gives back the anchors, the baro
/// reference and the kept instances, and across an outage of at most `init.resume_max_outage_s`
/// the pose too, moved by v·Δt with its covariance grown by the largest acceleration and rotation
/// rate assumed meanwhile (`init.resume_max_acc_m_s2`, `init.resume_max_rate_deg_s`).
/// The kept instances (Restart::kKept: baro bias, height bias, tag γ) come back with their value
/// and marginal covariance grown by their random walk over Δt, whatever the outage.
/// Cross-covariances between instances are not kept (marginals only), as in a recovery.
///
/// Files in the state folder (written atomically: a temporary file, then rename; docs/formats.md):
///   estimator_state.yaml   layout 2: `format: meshnav_estimator_state`, `version: 2`, t [s],
///                          landed, baro_reference_pa (null: none), `instances`: a list of
///                          {kind, id, peers (per-peer kinds only), value, cov}, the IMU first
///                          (value: the kind's toVector, cov: its error-state covariance
///                          row-major). A file without `version` (layout 1, before issue 11) is
///                          refused naming the file.
///   estimator_anchors.yaml the calibration results format (common/anchor_init_io.h)

#include <optional>
#include <string>
#include <vector>

#include "common/time.h"
#include "common/types.h"
#include "estimator/core/imu_state.h"

namespace meshnav::estimator {

/// One instance in a checkpoint, in its kind's vector form (K::toVector / K::fromVector).
struct InstanceRecord {
  std::string kind;             ///< K::kName
  SensorId id = 0;
  std::vector<SensorId> peers;  ///< the peers of per-peer states (anchor, tag); empty otherwise
  Eigen::VectorXd value;        ///< K::toVector of the nominal value
  Eigen::MatrixXd cov;          ///< marginal covariance of its error state
};

/// Throws std::invalid_argument unless `r` is a valid instance of a registered kind (its name, the
/// value's length for its peers, a covariance that fits (K::check) and is positive definite).
void checkInstanceRecord(const InstanceRecord& r);

struct EstimatorCheckpoint {
  static constexpr int kVersion = 2;  ///< the estimator_state.yaml layout written and read
  Timestamp t;                        ///< the instant the state is valid at (data time)
  SensorId imu_id = 1;
  ImuState imu;
  ImuMatrix cov_imu = ImuMatrix::Identity();
  bool landed = false;
  std::optional<double> baro_reference_pa;
  std::vector<InstanceRecord> instances;  ///< the kept instances of every other kind (Restart::kKept)
  std::vector<AnchorInit> anchors;        ///< estimated anchors: marginal covariance, pair biases
  /// The record of instance `id` of kind `kind`, or nullptr.
  const InstanceRecord* find(const std::string& kind, SensorId id) const;
};

/// Writes the two files into `dir` (created). Throws std::runtime_error naming the file.
/// `with_anchors` false: estimator_state.yaml only, the anchors' file written before stays (unless
/// there is none). The anchors' file is most of a checkpoint's cost (about 20 kB of YAML per
/// estimated anchor with its pair biases: 0.4 MB, ~25 ms, for the 20 fly-by anchors of a vehicle
/// among 100) while an anchor's estimate moves by millimetres per second; the estimator process
/// writes it every `--anchors-period` of data time and whenever the set of anchors changes.
void writeCheckpoint(const EstimatorCheckpoint& c, const std::string& dir, bool with_anchors = true);
/// Whether `dir` holds an anchors' file (else the next writeCheckpoint writes c.anchors, so its
/// checkpoint must hold them: makeCheckpoint's `with_anchors`).
bool checkpointHasAnchorsFile(const std::string& dir);
/// Reads them back; nullopt when `dir` holds no checkpoint. Throws std::runtime_error naming the
/// file and key on a malformed or non-finite one, or on a file of another layout version.
std::optional<EstimatorCheckpoint> readCheckpoint(const std::string& dir);

}  // namespace meshnav::estimator
