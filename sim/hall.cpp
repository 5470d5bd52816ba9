#include "sim/hall.h"

#include <sstream>

namespace meshnav::sim {

std::string Hall::toString() const {
  std::ostringstream s;
  const Eigen::Vector3d d = size();
  s << "hall " << d.x() << " x " << d.y() << " x " << d.z() << " m, x [" << min_m.x() << ", " << max_m.x() << "], y ["
    << min_m.y() << ", " << max_m.y() << "], z [" << min_m.z() << ", " << max_m.z() << "] m";
  return s.str();
}

}  // namespace meshnav::sim
