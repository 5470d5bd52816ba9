/// @file filter_context.cpp
/// @brief FilterContext: its copy and the replacement of the IMU block.
#include "estimator/node/filter_context.h"

#include "estimator/filter/strategy_factory.h"

namespace meshnav::estimator {

FilterContext FilterContext::copy() const {
  FilterContext s;
  s.filter = filter ? filter->clone() : nullptr;
  s.network = network;
  s.last_imu = last_imu;
  s.prev_imu = prev_imu;
  s.landed = landed;
  s.last_zupt = last_zupt;
  s.rest_rate = rest_rate;
  s.last_carried_height = last_carried_height;
  s.noise_adapter = noise_adapter;
  s.range_errors = range_errors;
  s.mean_reading = mean_reading;
  return s;
}

void FilterContext::replaceImu(const ImuState& x, const ImuMatrix& P, Timestamp t, const ImuSample& last,
                               const EstimatorOptions& options, SensorId imu_id, double gravity_z_sign) {
  mean_reading.reset();  // low-passed in the attitude and gravity being replaced
  const FusionStrategy& old = *filter;
  const NominalState& s = old.state();
  auto f = makeStrategy(options, gravity_z_sign);
  f->reset(imu_id, x, P, t);
  forEachKind([&]<class K>() {
    if constexpr (!K::kBody)
      for (const auto& [id, value] : s.values<K>())
        f->addInstance<K>(id, value, K::keptCovariance(old.covariance(id, id), options));
  });
  // DAH joint sets stay together (their members' cross-covariances restart from zero like all others).
  forEachKind([&]<class K>() {
    if constexpr (!K::kBody)
      for (const auto& [id, value] : s.values<K>())
        if (const std::vector<SensorId> set = old.jointSetOf(id); !set.empty()) f->joinJointSet(set);
  });
  filter = std::move(f);
  last_imu = last;
  prev_imu.reset();
  last_zupt = t;
  rest_rate.reset();
}

}  // namespace meshnav::estimator
