#include "calibrator/calibration_io.h"

#include "common/anchor_init_io.h"

namespace meshnav::calib {

void writeCalibrationYaml(const std::vector<CalibrationResult>& results, const std::string& path) {
  std::vector<AnchorInit> inits;
  std::vector<RefusedAnchor> refused;
  for (const auto& r : results) {
    if (r.ok()) inits.push_back(r.toAnchorInit());
    else refused.push_back({r.anchor_id, toString(r.status), r.reason});
  }
  writeAnchorInitsYaml(inits, path, refused);
}

}  // namespace meshnav::calib
