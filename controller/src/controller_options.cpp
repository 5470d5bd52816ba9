#include "controller/controller_options.h"

#include <stdexcept>
#include <variant>

#include "common/options_list.h"

namespace meshnav::controller {

namespace {

using Ref = std::variant<double*>;

template <auto... path>
constexpr auto at = &memberAt<ControllerOptions, Ref, path...>;

const OptionField<ControllerOptions, Ref> kFields[] = {
    {"kp_xy_per_s", at<&ControllerOptions::kp_xy_per_s>, "[1/s]"},
    {"kp_z_per_s", at<&ControllerOptions::kp_z_per_s>, "[1/s]"},
    {"kv_xy_per_s", at<&ControllerOptions::kv_xy_per_s>, "[1/s]"},
    {"kv_z_per_s", at<&ControllerOptions::kv_z_per_s>, "[1/s]"},
    {"ki_xy_per_s2", at<&ControllerOptions::ki_xy_per_s2>, "[1/s^2]"},
    {"ki_z_per_s2", at<&ControllerOptions::ki_z_per_s2>, "[1/s^2]"},
    {"integral_limit_m_s2", at<&ControllerOptions::integral_limit_m_s2>, "[m/s^2]"},
    {"k_tilt_per_s", at<&ControllerOptions::k_tilt_per_s>, "[1/s]"},
    {"k_yaw_per_s", at<&ControllerOptions::k_yaw_per_s>, "[1/s]"},
    {"max_speed_xy_m_s", at<&ControllerOptions::max_speed_xy_m_s>, "[m/s]"},
    {"max_speed_z_m_s", at<&ControllerOptions::max_speed_z_m_s>, "[m/s]"},
    {"max_acc_xy_m_s2", at<&ControllerOptions::max_acc_xy_m_s2>, "[m/s^2]"},
    {"max_tilt_deg", at<&ControllerOptions::max_tilt_deg>, "[deg]"},
    {"max_rate_rad_s", at<&ControllerOptions::max_rate_rad_s>, "[rad/s]"},
    {"max_thrust_m_s2", at<&ControllerOptions::max_thrust_m_s2>, "[m/s^2]"},
    {"pose_timeout_s", at<&ControllerOptions::pose_timeout_s>, "[s]"},
    {"max_position_cov_trace_m2", at<&ControllerOptions::max_position_cov_trace_m2>, "[m^2]"},
    {"recover_after_s", at<&ControllerOptions::recover_after_s>, "[s]"},
    {"failsafe_descent_acc_m_s2", at<&ControllerOptions::failsafe_descent_acc_m_s2>, "[m/s^2]"},
    {"spin_up_s", at<&ControllerOptions::spin_up_s>, "[s]"},
};

template <typename Opts, typename F>
void visitOptions(Opts& o, F&& f) {
  forEachOption(o, kFields, f);
}

}  // namespace

ControllerOptions ControllerOptions::fromYaml(const YAML::Node& node, const std::string& where) {
  YamlOptions yaml(node, where, "");
  return readOptionsList<ControllerOptions>(yaml, [](auto& o, auto&& f) { visitOptions(o, f); });
}

ControllerOptions ControllerOptions::load(const std::string& path) {
  if (path.empty()) return ControllerOptions{};
  return fromYaml(YamlOptions::loadFile(path), path);
}

void ControllerOptions::validate() const {
  auto require = [](bool ok, const char* key, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("key '") + key + "' must be " + what);
  };
  require(kp_xy_per_s > 0.0, "kp_xy_per_s", "> 0");
  require(kp_z_per_s > 0.0, "kp_z_per_s", "> 0");
  require(kv_xy_per_s > 0.0, "kv_xy_per_s", "> 0");
  require(kv_z_per_s > 0.0, "kv_z_per_s", "> 0");
  require(ki_xy_per_s2 >= 0.0, "ki_xy_per_s2", ">= 0");
  require(ki_z_per_s2 >= 0.0, "ki_z_per_s2", ">= 0");
  require(integral_limit_m_s2 >= 0.0, "integral_limit_m_s2", ">= 0");
  require(k_tilt_per_s > 0.0, "k_tilt_per_s", "> 0");
  require(k_yaw_per_s > 0.0, "k_yaw_per_s", "> 0");
  require(max_speed_xy_m_s > 0.0, "max_speed_xy_m_s", "> 0");
  require(max_speed_z_m_s > 0.0, "max_speed_z_m_s", "> 0");
  require(max_acc_xy_m_s2 > 0.0, "max_acc_xy_m_s2", "> 0");
  require(max_tilt_deg > 0.0 && max_tilt_deg < 80.0, "max_tilt_deg", "in (0, 80)");
  require(max_rate_rad_s > 0.0, "max_rate_rad_s", "> 0");
  require(max_thrust_m_s2 > 9.81, "max_thrust_m_s2", "> g (9.81)");
  require(pose_timeout_s > 0.0, "pose_timeout_s", "> 0");
  require(max_position_cov_trace_m2 > 0.0, "max_position_cov_trace_m2", "> 0");
  require(recover_after_s >= 0.0, "recover_after_s", ">= 0");
  require(failsafe_descent_acc_m_s2 > 0.0 && failsafe_descent_acc_m_s2 < 9.81, "failsafe_descent_acc_m_s2",
          "in (0, g)");
  require(spin_up_s >= 0.0, "spin_up_s", ">= 0");
}

std::string ControllerOptions::toString() const {
  return printOptionsList(*this, [](auto& o, auto&& f) { visitOptions(o, f); });
}

}  // namespace meshnav::controller
