#include "transport/fleet_bus.h"

#include <charconv>
#include <stdexcept>

namespace meshnav::transport {

const char* toString(FleetBus bus) { return bus == FleetBus::kShared ? "shared" : "per-vehicle"; }

FleetBus parseFleetBus(std::string_view name) {
  if (name == "shared") return FleetBus::kShared;
  if (name == "per-vehicle") return FleetBus::kPerVehicle;
  throw std::invalid_argument("fleet bus '" + std::string(name) + "': expected shared or per-vehicle");
}

std::string vehicleLcmUrl(FleetBus bus, const std::string& base_url, size_t vehicle_index) {
  if (bus == FleetBus::kShared) return base_url;
  constexpr std::string_view kScheme = "udpm://";
  if (base_url.rfind(kScheme, 0) != 0)
    throw std::invalid_argument("a bus per vehicle needs a udpm:// LCM URL, got '" + base_url + "'");
  const size_t query = base_url.find('?');
  const std::string network = base_url.substr(kScheme.size(), query == std::string::npos ? std::string::npos
                                                                                        : query - kScheme.size());
  const std::string options = query == std::string::npos ? "" : base_url.substr(query);
  const size_t colon = network.rfind(':');
  const std::string group = network.substr(0, colon);
  if (group.empty()) throw std::invalid_argument("LCM URL '" + base_url + "' names no multicast group");
  int port = kLcmDefaultUdpmPort;
  if (colon != std::string::npos) {
    const std::string_view digits = std::string_view(network).substr(colon + 1);
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), port);
    if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size() || port <= 0 || port > 65535)
      throw std::invalid_argument("LCM URL '" + base_url + "': port '" + std::string(digits) + "' is no port number");
  }
  const size_t vehicle_port = static_cast<size_t>(port) + 1 + vehicle_index;
  if (vehicle_port > 65535)
    throw std::invalid_argument("LCM URL '" + base_url + "': vehicle " + std::to_string(vehicle_index) +
                                "'s bus would be port " + std::to_string(vehicle_port) + " (> 65535)");
  return std::string(kScheme) + group + ":" + std::to_string(vehicle_port) + options;
}

}  // namespace meshnav::transport
