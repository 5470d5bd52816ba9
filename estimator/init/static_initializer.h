#pragma once
/// @file static_initializer.h
/// @brief Initial belief from data collected while landed (before the filter runs).
///
///  - roll, pitch from the mean specific force f̄ (at rest f = Rᵀ[0, 0, |g|]):
///    roll = atan2(f̄_y, f̄_z), pitch = atan2(−f̄_x, √(f̄_y² + f̄_z²)); gyro bias = mean ω;
///  - position and yaw from setup.initial_pose (σ_p, σ_yaw) when given, otherwise from a
///    least-squares fit of [p_IinG, yaw] to the bias-corrected tag ranges to known anchors
///    ((z − γ)/β = ‖p_A − p_IinG − R(yaw) p_TinI‖, Gauss–Newton from a grid of starts with Cauchy
///    weights, residuals beyond `range_init_outlier_m` at its best minimum dropped, each distinct
///    minimum descended again over the inliers with Huber weights, whose costs decide; a weak yaw
///    prior of σ π keeps the normal matrix regular). Refused while the fit cannot fix the pose: yaw σ above
///    `static_max_sigma_yaw_deg` (one tag: only its lever arm shows yaw at rest), a second
///    local minimum as good as the best (nearly coplanar anchors mirror the position); the node
///    then waits for motion (MotionAligner). The fit's covariance is scaled by the robust
///    variance factor of its residuals (huber::varianceFactor);
///  - baro reference pressure from setup or the mean landed pressure; bias so that the mean
///    height matches the initial baro height.
/// The orientation covariance is local (I): Σ_θ = σ_rp² (I − n nᵀ) + σ_yaw² n nᵀ, n = R̂ᵀ e_z.

#include <optional>
#include <string>
#include <vector>

#include "common/setup.h"
#include "common/types.h"
#include "estimator/core/estimator_options.h"
#include "estimator/core/imu_state.h"
#include "estimator/uwb/uwb_network.h"

namespace meshnav::estimator {

struct InitialBelief {
  Timestamp t;
  ImuState imu;
  ImuMatrix cov = ImuMatrix::Identity();
  bool from_ranges = false;
  bool from_checkpoint = false;      ///< resumed from an EstimatorCheckpoint (a restart)
  double range_fit_rms_m = 0.0;      ///< RMS residual of the range fit [m]
  int n_ranges_used = 0;
  std::optional<double> baro_reference_pa;  ///< none: no baro data and none in setup
  double baro_bias_m = 0.0;
  double baro_bias_var_m2 = 1.0;
  ImuSample last_imu;                ///< the IMU reading the belief is valid at
  bool landed = true;                ///< flight state at initialization
  /// The downward rangefinder's bias when the initialization estimated it (in-motion alignment
  /// with heights): mean [m] and variance [m²]. None: the node's prior (0, height.init_bias_sigma_m²).
  std::optional<std::pair<double, double>> height_bias;
  int n_heights_used = 0;
  /// The sign s of gravity g_G = (0, 0, s|g|) that the first in-motion alignment's window decided
  /// by comparing both (MotionAligner::checkGravityDirection, the pose fitted with it); 0: not
  /// compared (landed, vertical sensors, a later alignment) or undecided.
  int gravity_z_sign = 0;
};

class StaticInitializer {
 public:
  /// The robust loss of a fit: Cauchy for the first search, which only tells the outliers (a gross
  /// outlier's pull vanishes, so it cannot pick between minima the inliers leave alike); Huber for
  /// the second search over the inliers, whose minima decide ambiguity, and for the refinement
  /// (its covariance is the one the filter starts from).
  enum class FitLoss { kCauchy, kHuber };
  /// A local minimum of the static range fit from one start.
  struct FitMinimum {
    double cost;
    Eigen::Vector3d p;
    double yaw;
  };
  StaticInitializer(const EstimatorOptions& options, const SystemSetup& setup);

  void addFlightState(const FlightStateSample& s);
  /// IMU stillness (StillnessDetector): the evidence of rest while no flight state was received.
  void addStillness(bool still);
  /// Whether the data says the body rests (flight state, else stillness, else the option).
  bool isStatic() const;
  void addImu(const ImuSample& s);
  void addBaro(const BaroSample& s);
  /// Ranges between a tag and a known anchor (from setup) are kept; others are ignored.
  void addRange(const RangeSample& s);

  /// The initial belief at the latest IMU sample's time, once enough landed data is there.
  std::optional<InitialBelief> tryInitialize();
  /// What the initializer still waits for (for logs).
  std::string waitingFor() const { return waiting_for_; }

 private:
  struct InitRange {
    SensorId tag = 0;
    SensorId anchor = 0;
    double d_m = 0.0;      // bias-corrected distance
    double sigma_m = 0.1;
  };
  void restart();
  std::optional<InitialBelief> build(const Eigen::Matrix3d& R_rp);

  /// Iteratively reweighted Gauss–Newton on [p, yaw] over the ranges marked in `use` with the
  /// weights of `loss` (scale 2σ); returns the cost Σ ρ(e_i), e_i = (d_i − ‖p_A − p − R p_T‖)/σ_i,
  /// plus ρ((z_h − p_z)/σ_h) of the height prior when there is one.
  double solveFit(const Eigen::Matrix3d& R_rp, const std::vector<bool>& use, Eigen::Vector3d& p, double& yaw,
                  Eigen::Matrix4d* cov, FitLoss loss) const;
  /// A prior on the IMU's height for the range fit from what else knows it: the barometer when
  /// the setup gives its reference pressure (h = height from the mean pressure minus the baro's
  /// lever arm, σ² = baro.init_bias_sigma_m² + the pressure noise over the samples), else the
  /// setup's carried height (σ² = its sigma_m² + carried_height.sigma_m²). Without one, nearly
  /// coplanar anchors leave the height's mirror image to the ambiguity check alone.
  struct HeightPrior {
    double z_m = 0.0;
    double sigma_m = 1.0;
  };
  std::optional<HeightPrior> heightPrior(const Eigen::Matrix3d& R_rp) const;
  /// Starts of the fit on a grid (3 × 3 positions around the anchors' centroid at three or four
  /// heights, four headings) and the minimum each reaches over the ranges in `use`.
  std::vector<FitMinimum> searchMinima(const Eigen::Matrix3d& R_rp, const std::vector<bool>& use,
                                       const Eigen::Vector3d& centroid, FitLoss loss) const;
  /// The distinct minima among `starts` (0.05 m, 2° apart), each descended again over the ranges
  /// in `use` with Huber weights, with its cost there.
  std::vector<FitMinimum> refineDistinct(const Eigen::Matrix3d& R_rp, const std::vector<bool>& use,
                                         const std::vector<FitMinimum>& starts) const;
  /// d_i − ‖p_A − p − R p_T‖ of range i [m].
  double rangeResidual(size_t i, const Eigen::Matrix3d& R, const Eigen::Vector3d& p) const;
  /// Marks the ranges within `range_init_outlier_m` of the pose `at`; returns their number.
  int markInliers(const Eigen::Matrix3d& R_rp, const FitMinimum& at, std::vector<bool>& use) const;
  /// Least-squares [p, yaw]; returns false when it does not converge.
  bool fitPoseToRanges(const Eigen::Matrix3d& R_rp, Eigen::Vector3d& p, double& yaw, Eigen::Matrix4d& cov,
                       double& rms, int& n_used);

  EstimatorOptions options_;
  SystemSetup setup_;
  UwbNetwork network_;
  std::optional<bool> landed_;
  bool still_ = false;
  bool took_off_ = false;
  std::optional<Timestamp> static_since_;
  std::optional<ImuSample> last_imu_;
  int n_imu_ = 0;
  Eigen::Vector3d sum_acc_ = Eigen::Vector3d::Zero(), sum_gyro_ = Eigen::Vector3d::Zero();
  int n_baro_ = 0;
  double sum_pressure_ = 0.0;
  std::vector<InitRange> ranges_;
  std::optional<HeightPrior> height_prior_;  ///< of the fit in progress (fitPoseToRanges)
  static constexpr size_t kMaxRanges = 600;   ///< newest ranges kept for the fit (≈ 10 s at 60 Hz)
  static constexpr double kRetryS = 0.5;      ///< a refused range fit is retried after this much data time [s]
  std::optional<Timestamp> last_fit_t_;       ///< data time of the last range fit
  std::string waiting_for_ = "landed IMU data";
};

}  // namespace meshnav::estimator
