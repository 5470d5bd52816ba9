#include "common/chi_square.h"

#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

namespace meshnav {

double chi2Cdf(double x, double dof) {
  if (!(dof > 0.0) || !std::isfinite(dof) || !(x >= 0.0) || !std::isfinite(x))
    throw std::invalid_argument("chi2Cdf: need dof > 0 and finite x >= 0 (dof " + std::to_string(dof) + ", x " +
                                std::to_string(x) + ")");
  return boost::math::cdf(boost::math::chi_squared_distribution<double>(dof), x);
}

double chi2Quantile(double dof, double p) {
  if (!(dof > 0.0) || !std::isfinite(dof) || !(p > 0.0 && p < 1.0))
    throw std::invalid_argument("chi2Quantile: need dof > 0 and 0 < p < 1 (dof " + std::to_string(dof) + ", p " +
                                std::to_string(p) + ")");
  return boost::math::quantile(boost::math::chi_squared_distribution<double>(dof), p);
}

}  // namespace meshnav
