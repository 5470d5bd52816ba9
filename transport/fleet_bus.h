#pragma once
/// @file fleet_bus.h
/// @brief Which LCM bus (udpm group and port) each vehicle of a fleet over LCM talks on
/// (docs/fleet.md, "A fleet over LCM"; docs/decisions/017-bus-per-vehicle.md).
///
/// LCM's udpm provider hands every datagram of its group and port to every process bound to it;
/// a process drops the channels it did not subscribe in user space, after its receive thread has
/// woken for them. On one bus each of the fleet's N vehicles therefore pays for the traffic of
/// all N. With `FleetBus::kPerVehicle` vehicle k (its index in the fleet file, from 0) gets the
/// base URL with port `base_port + 1 + k`: the kernel delivers a vehicle's datagrams only to that
/// vehicle's processes. The channel prefixes stay (`v0/POSE` on v0's bus): the channel names are
/// still the one naming, and a capture of several buses stays unambiguous.
///
/// The same function names the buses for the launch file (transport/fleet_launch.h) and for the
/// probe that listens on them (meshnav_lcm_probe --fleet), so the two cannot disagree.

#include <cstddef>
#include <string>
#include <string_view>

namespace meshnav::transport {

/// How the vehicles of a fleet share LCM.
enum class FleetBus {
  kShared,      ///< every vehicle on the one base URL (before issue 38's measurement)
  kPerVehicle,  ///< vehicle k on the base URL's port + 1 + k (the default)
};

/// "shared" / "per-vehicle".
const char* toString(FleetBus bus);
/// The FleetBus named `name` ("shared", "per-vehicle"); throws std::invalid_argument naming the
/// accepted values for anything else.
FleetBus parseFleetBus(std::string_view name);

/// LCM's own default port of udpm (used when a udpm URL names none).
inline constexpr int kLcmDefaultUdpmPort = 7667;

/// The URL of vehicle `vehicle_index`'s bus: `base_url` itself for kShared; for kPerVehicle the
/// same udpm group and options with port `p + 1 + vehicle_index`, p = the base URL's port (7667
/// when it names none): "udpm://239.255.76.67:7667?ttl=0", 2 -> "udpm://239.255.76.67:7670?ttl=0".
/// Throws std::invalid_argument for kPerVehicle with a URL that is not udpm://GROUP[:PORT][?OPTIONS]
/// (memq:// has no port: each process is its own bus anyway), a malformed port, or a resulting
/// port above 65535.
std::string vehicleLcmUrl(FleetBus bus, const std::string& base_url, size_t vehicle_index);

}  // namespace meshnav::transport
