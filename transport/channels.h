#pragma once
/// @file channels.h
/// @brief LCM channel names (docs/channels.md), UPPER_SNAKE. Every process uses these constants; a
/// launch file may remap nothing, so the names are the contract between processes.

namespace meshnav::channels {

inline constexpr const char* kImu = "IMU";                          ///< imu_t, imu_bridge → estimator
inline constexpr const char* kBaro = "BARO";                        ///< baro_t
inline constexpr const char* kRange = "RANGE";                      ///< range_t, uwb_bridge → estimator, calibrator
inline constexpr const char* kFlightState = "FLIGHT_STATE";         ///< flight_state_t
inline constexpr const char* kHeight = "HEIGHT";                    ///< height_t, imu_bridge → estimator
inline constexpr const char* kGroundTruth = "GROUND_TRUTH";         ///< ground_truth_t (simulator, logs)
inline constexpr const char* kAnchorInit = "ANCHOR_INIT";           ///< anchor_init_t, calibrator → estimator
inline constexpr const char* kPose = "POSE";                        ///< pose_t, estimator →
inline constexpr const char* kAnchors = "ANCHORS";                  ///< anchors_t, estimator →
inline constexpr const char* kEstimatorStatus = "ESTIMATOR_STATUS"; ///< estimator_status_t (heartbeat)
inline constexpr const char* kEstimatorCmd = "ESTIMATOR_CMD";       ///< estimator_cmd_t, mission → estimator
inline constexpr const char* kCalibCmd = "CALIB_CMD";               ///< calib_cmd_t, mission → calibrator
inline constexpr const char* kCalibStatus = "CALIB_STATUS";         ///< calib_status_t (heartbeat)
inline constexpr const char* kMissionStatus = "MISSION_STATUS";     ///< mission_status_t (heartbeat)
inline constexpr const char* kTimeSyncRequest = "TIME_SYNC_REQUEST"; ///< time_sync_t, bridges → estimator (clock reference)
inline constexpr const char* kTimeSync = "TIME_SYNC";                ///< time_sync_t, estimator → bridges (replies)

/// Every channel above, for tools that list or record them.
inline constexpr const char* kAll[] = {kImu,         kBaro,           kRange,           kFlightState,
                                       kGroundTruth, kAnchorInit,     kPose,            kAnchors,
                                       kEstimatorStatus, kEstimatorCmd, kCalibCmd,     kCalibStatus,
                                       kMissionStatus, kHeight, kTimeSyncRequest, kTimeSync};

}  // namespace meshnav::channels
