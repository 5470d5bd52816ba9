#include "calibrator/calibrator_options.h"

#include "common/options_list.h"

#include <sstream>
#include <stdexcept>
#include <variant>

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

/// Where an option lives: a pointer to the member, of one of the types its options have.
using Ref = std::variant<double*, int*, bool*, uint64_t*, RobustLoss*>;

template <auto... path>
constexpr auto at = &memberAt<CalibratorOptions, Ref, path...>;

/// Every option as (key, member): the one list reading and printing share.
const OptionField<CalibratorOptions, Ref> kFields[] = {
    {"sigma_range", at<&CalibratorOptions::sigma_range_m>},
    {"gamma_prior_sigma", at<&CalibratorOptions::gamma_prior_sigma_m>},
    {"beta_prior_sigma", at<&CalibratorOptions::beta_prior_sigma>},
    {"estimate_beta", at<&CalibratorOptions::estimate_beta>},
    {"beta_min_range_spread", at<&CalibratorOptions::beta_min_range_spread_m>},
    {"moving_min_spread", at<&CalibratorOptions::moving_min_spread_m>},
    {"linear_bias_correction", at<&CalibratorOptions::linear_bias_correction>},
    {"linear_passes", at<&CalibratorOptions::linear_passes>},
    {"robust_loss", at<&CalibratorOptions::robust_loss>},
    {"robust_loss_scale", at<&CalibratorOptions::robust_loss_scale>},
    {"lm_max_iterations", at<&CalibratorOptions::lm_max_iterations>},
    {"ransac", at<&CalibratorOptions::ransac>},
    {"ransac_seed", at<&CalibratorOptions::ransac_seed>},
    {"ransac_threshold_sigmas", at<&CalibratorOptions::ransac_threshold_sigmas>},
    {"ransac_confidence", at<&CalibratorOptions::ransac_confidence>},
    {"ransac_min_iterations", at<&CalibratorOptions::ransac_min_iterations>},
    {"ransac_max_iterations", at<&CalibratorOptions::ransac_max_iterations>},
    {"ransac_rows_margin", at<&CalibratorOptions::ransac_rows_margin>},
    {"scale_covariance_by_residuals", at<&CalibratorOptions::scale_covariance_by_residuals>},
    {"correlated_reference_fraction", at<&CalibratorOptions::correlated_reference_fraction>},
    {"outlier_threshold_sigmas", at<&CalibratorOptions::outlier_threshold_sigmas>},
    {"min_measurements", at<&CalibratorOptions::min_measurements>},
    {"min_measurements_per_reference", at<&CalibratorOptions::min_measurements_per_reference>},
    {"min_distinct_positions", at<&CalibratorOptions::min_distinct_positions>},
    {"distinct_position_resolution", at<&CalibratorOptions::distinct_position_resolution_m>},
    {"min_plane_spread", at<&CalibratorOptions::min_plane_spread_m>},
    {"min_line_spread", at<&CalibratorOptions::min_line_spread_m>},
    {"max_position_sigma", at<&CalibratorOptions::max_position_sigma_m>},
    {"mirror_reference_min_offset", at<&CalibratorOptions::mirror_reference_min_offset_m>},
    {"mirror_max_plane_spread", at<&CalibratorOptions::mirror_max_plane_spread_m>},
    {"mirror_max_normal_sigma", at<&CalibratorOptions::mirror_max_normal_sigma_m>},
    {"mirror_min_cost_gap", at<&CalibratorOptions::mirror_min_cost_gap>},
    {"mirror_merge_max", at<&CalibratorOptions::mirror_merge_max_m>},
    {"use_range_variance", at<&CalibratorOptions::use_range_variance>},
    {"max_pose_gap", at<&CalibratorOptions::max_pose_gap_s>},
    {"min_tag_position_sigma", at<&CalibratorOptions::min_tag_position_sigma_m>},
};

std::string fmtNumber(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

/// Visits every option as (key, field, unit).
template <typename Opts, typename F>
void visitOptions(Opts& o, F&& f) {
  forEachOption(o, kFields, f);
}

}  // namespace

void readOption(YamlOptions& yaml, const std::string& key, RobustLoss& field) {
  std::string name = toString(field);
  yaml.read(key, name);
  try {
    field = robustLossFromString(name);
  } catch (const std::exception& e) {
    yaml.fail(key, e.what());
  }
}

void printOption(std::ostream& os, RobustLoss value) { os << toString(value); }

CalibratorOptions CalibratorOptions::fromYaml(const YAML::Node& node, const std::string& where) {
  // The one rule of common/yaml_options.h (missing: default; unknown or bad: file and key).
  YamlOptions yaml(node, where, "calibrator");
  return readOptionsList<CalibratorOptions>(yaml, [](auto& o, auto&& f) { visitOptions(o, f); });
}

void CalibratorOptions::validate() const {
  auto positive = [](double v, const char* key) {
    if (!(v > 0.0)) throw std::runtime_error("key 'calibrator." + std::string(key) + "' must be > 0");
  };
  positive(sigma_range_m, "sigma_range");
  positive(robust_loss_scale, "robust_loss_scale");
  positive(ransac_threshold_sigmas, "ransac_threshold_sigmas");
  positive(outlier_threshold_sigmas, "outlier_threshold_sigmas");
  positive(distinct_position_resolution_m, "distinct_position_resolution");
  if (!(mirror_min_cost_gap >= 0.0)) throw std::runtime_error("key 'calibrator.mirror_min_cost_gap' must be >= 0");
  if (!(ransac_confidence > 0.0 && ransac_confidence < 1.0))
    throw std::runtime_error("key 'calibrator.ransac_confidence' must be in (0, 1)");
  if (ransac_min_iterations < 1 || ransac_max_iterations < ransac_min_iterations)
    throw std::runtime_error("need 1 <= ransac_min_iterations <= ransac_max_iterations");
  // Every other number that a value out of range would break later, without naming the key.
  auto within = [](double v, double lo, double hi, const char* key) {
    if (!(v >= lo && v <= hi))
      throw std::runtime_error("key 'calibrator." + std::string(key) + "' must be in [" + fmtNumber(lo) + ", " +
                               fmtNumber(hi) + "], got " + fmtNumber(v));
  };
  within(max_pose_gap_s, 1e-3, 3600.0, "max_pose_gap");
  within(lm_max_iterations, 1, 100000, "lm_max_iterations");
  within(linear_passes, 0, 100, "linear_passes");
  within(ransac_rows_margin, 0, 100, "ransac_rows_margin");
  within(min_measurements, 1, 1e9, "min_measurements");
  within(min_measurements_per_reference, 1, 1e9, "min_measurements_per_reference");
  within(min_distinct_positions, 1, 1e9, "min_distinct_positions");
  within(min_plane_spread_m, 0.0, 1e3, "min_plane_spread");
  within(min_line_spread_m, 0.0, 1e3, "min_line_spread");
  within(max_position_sigma_m, 1e-6, 1e6, "max_position_sigma");
  within(correlated_reference_fraction, 0.0, 1.0, "correlated_reference_fraction");
  within(min_tag_position_sigma_m, 0.0, 1e3, "min_tag_position_sigma");
  within(moving_min_spread_m, 0.0, 1e3, "moving_min_spread");
  within(beta_min_range_spread_m, 0.0, 1e3, "beta_min_range_spread");
  within(mirror_max_plane_spread_m, 0.0, 1e3, "mirror_max_plane_spread");
  within(mirror_max_normal_sigma_m, 0.0, 1e3, "mirror_max_normal_sigma");
  within(mirror_merge_max_m, 0.0, 1e3, "mirror_merge_max");
}

std::string CalibratorOptions::toString() const {
  return printOptionsList(*this, [](auto& o, auto&& f) { visitOptions(o, f); });
}

}  // namespace meshnav::calib
