#include "sim/sensor_fault_cli.h"

namespace meshnav::sim {

SensorFaultOptions SensorFaultArgs::options() const {
  SensorFaultOptions o;
  if (imu_gap.size() == 2) o.imu_gaps_s.push_back({imu_gap[0], imu_gap[1]});
  if (anchor_off != 0) {
    o.anchor_off = static_cast<SensorId>(anchor_off);
    o.anchor_off_from_s = anchor_off_at_s;
  }
  o.range_loss_fraction = range_loss;
  o.range_loss_from_s = range_loss_from_s;
  o.validate();
  return o;
}

void declareSensorFaultOptions(Cli& cli, SensorFaultArgs& a, bool with_imu_gap) {
  if (with_imu_gap)
    cli.optional("imu-gap", a.imu_gap, "drill: no IMU to the estimator from A to B seconds (--imu-gap A,B)")
        ->delimiter(',')
        ->expected(2);
  cli.optional("anchor-off", a.anchor_off, "drill: switch this anchor off at --anchor-off-at (its ranges stop)")
      ->type_name("ID")
      ->check(CLI::Range(int64_t{1}, int64_t{0xFFFFFFFF}));
  cli.option("anchor-off-at", a.anchor_off_at_s, "drill: time the anchor goes off [s]")->check(cli::nonNegative());
  cli.option("range-loss", a.range_loss, "drill: fraction of RANGE lost from --range-loss-from (e.g. 0.2)")
      ->check(CLI::Range(0.0, 0.99));
  cli.option("range-loss-from", a.range_loss_from_s, "drill: time the RANGE loss starts [s]")->check(cli::nonNegative());
}

}  // namespace meshnav::sim
