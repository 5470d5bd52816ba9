#include "estimator/filter/strategy_factory.h"

#include <stdexcept>

#include "estimator/core/strategy_list.h"
#include "estimator/filter/centralized_ekf.h"
#include "estimator/filter/modular_filter.h"

namespace meshnav::estimator {

std::unique_ptr<FusionStrategy> makeStrategy(const EstimatorOptions& o, double gravity_z_sign) {
  if (o.strategy == "centralized")
    return std::make_unique<CentralizedEkf>(ImuPropagator(o.gravity_m_s2, o.imu, gravity_z_sign),
                                            KindRandomWalks::fromOptions(o), o.joseph_form);
  if (o.strategy == "dp" || o.strategy == "dah")
    return std::make_unique<ModularFilter>(o.strategy == "dp" ? ModularFilter::Mode::DP : ModularFilter::Mode::DAH,
                                           ImuPropagator(o.gravity_m_s2, o.imu, gravity_z_sign),
                                           KindRandomWalks::fromOptions(o), o.joseph_form);
  throw std::invalid_argument("unknown strategy '" + o.strategy + "'");
}

}  // namespace meshnav::estimator
