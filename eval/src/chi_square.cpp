#include "eval/chi_square.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace meshnav::eval {

ChiSquareBounds aneesBounds(int n_samples, int dof, double confidence) {
  ChiSquareBounds b;
  if (n_samples <= 0 || dof <= 0) {
    b.lower = b.upper = std::numeric_limits<double>::quiet_NaN();
    return b;
  }
  const double alpha = 1.0 - confidence;
  const double k = static_cast<double>(n_samples) * dof;
  b.lower = chi2Quantile(k, 0.5 * alpha) / n_samples;
  b.upper = chi2Quantile(k, 1.0 - 0.5 * alpha) / n_samples;
  return b;
}

}  // namespace meshnav::eval
