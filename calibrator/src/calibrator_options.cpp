#include "calibrator/calibrator_options.h"

#include "common/yaml_options.h"

#include <sstream>
#include <stdexcept>

namespace meshnav::calib {

const char* toString(RobustLoss l) {
  switch (l) {
    case RobustLoss::None: return "none";
    case RobustLoss::Huber: return "huber";
    case RobustLoss::Cauchy: return "cauchy";
  }
  return "?";
}

RobustLoss robustLossFromString(const std::string& s) {
  if (s == "none") return RobustLoss::None;
  if (s == "huber") return RobustLoss::Huber;
  if (s == "cauchy") return RobustLoss::Cauchy;
  throw std::runtime_error("robust_loss must be none|huber|cauchy, got '" + s + "'");
}

namespace {

/// Visits every option as (key, reference) so that reading and printing share one list.
template <typename Opts, typename F>
void visitOptions(Opts& o, F&& f) {
  f("sigma_range", o.sigma_range_m);
  f("gamma_prior_sigma", o.gamma_prior_sigma_m);
  f("beta_prior_sigma", o.beta_prior_sigma);
  f("estimate_beta", o.estimate_beta);
  f("beta_min_range_spread", o.beta_min_range_spread_m);
  f("moving_min_spread", o.moving_min_spread_m);
  f("linear_bias_correction", o.linear_bias_correction);
  f("linear_passes", o.linear_passes);
  f("robust_loss", o.robust_loss);
  f("robust_loss_scale", o.robust_loss_scale);
  f("lm_max_iterations", o.lm_max_iterations);
  f("ransac", o.ransac);
  f("ransac_seed", o.ransac_seed);
  f("ransac_threshold_sigmas", o.ransac_threshold_sigmas);
  f("ransac_confidence", o.ransac_confidence);
  f("ransac_min_iterations", o.ransac_min_iterations);
  f("ransac_max_iterations", o.ransac_max_iterations);
  f("ransac_rows_margin", o.ransac_rows_margin);
  f("scale_covariance_by_residuals", o.scale_covariance_by_residuals);
  f("correlated_reference_fraction", o.correlated_reference_fraction);
  f("outlier_threshold_sigmas", o.outlier_threshold_sigmas);
  f("min_measurements", o.min_measurements);
  f("min_measurements_per_reference", o.min_measurements_per_reference);
  f("min_distinct_positions", o.min_distinct_positions);
  f("distinct_position_resolution", o.distinct_position_resolution_m);
  f("min_plane_spread", o.min_plane_spread_m);
  f("min_line_spread", o.min_line_spread_m);
  f("max_position_sigma", o.max_position_sigma_m);
  f("use_range_variance", o.use_range_variance);
  f("max_pose_gap", o.max_pose_gap_s);
  f("min_tag_position_sigma", o.min_tag_position_sigma_m);
}

template <typename T>
std::string printValue(const T& v) {
  std::ostringstream s;
  if constexpr (std::is_same_v<T, RobustLoss>) {
    s << toString(v);
  } else if constexpr (std::is_same_v<T, bool>) {
    s << (v ? "true" : "false");
  } else {
    s << v;
  }
  return s.str();
}

}  // namespace

CalibratorOptions CalibratorOptions::fromYaml(const YAML::Node& node, const std::string& where) {
  // The one rule of common/yaml_options.h (missing: default; unknown or bad: file and key).
  CalibratorOptions o;
  YamlOptions yaml(node, where, "calibrator");
  visitOptions(o, [&](const char* key, auto& ref) {
    if constexpr (std::is_same_v<std::remove_reference_t<decltype(ref)>, RobustLoss>) {
      std::string name = calib::toString(ref);
      yaml.read(key, name);
      try {
        ref = robustLossFromString(name);
      } catch (const std::exception& e) {
        yaml.fail(key, e.what());
      }
    } else {
      yaml.read(key, ref);
    }
  });
  yaml.rejectUnknown();
  auto positive = [&](double v, const char* key) {
    if (!(v > 0.0)) throw std::runtime_error(where + ": key 'calibrator." + std::string(key) + "' must be > 0");
  };
  positive(o.sigma_range_m, "sigma_range");
  positive(o.robust_loss_scale, "robust_loss_scale");
  positive(o.ransac_threshold_sigmas, "ransac_threshold_sigmas");
  positive(o.outlier_threshold_sigmas, "outlier_threshold_sigmas");
  positive(o.distinct_position_resolution_m, "distinct_position_resolution");
  if (!(o.ransac_confidence > 0.0 && o.ransac_confidence < 1.0))
    throw std::runtime_error(where + ": key 'calibrator.ransac_confidence' must be in (0, 1)");
  if (o.ransac_min_iterations < 1 || o.ransac_max_iterations < o.ransac_min_iterations)
    throw std::runtime_error(where + ": need 1 <= ransac_min_iterations <= ransac_max_iterations");
  return o;
}

std::string CalibratorOptions::toString() const {
  std::ostringstream s;
  auto copy = *this;
  visitOptions(copy, [&](const char* key, auto& ref) { s << "  " << key << ": " << printValue(ref) << "\n"; });
  return s.str();
}

}  // namespace meshnav::calib
