#pragma once
/// @file fleet_file.h
/// @brief The fleet file (docs/fleet.md): the vehicles of a fleet, each a name and a dataset folder.
/// Read by `meshnav run --fleet` (pipeline/fleet.h) and `meshnav eval --fleet`.

#include <string>
#include <string_view>
#include <vector>

namespace meshnav {

/// One entry of a fleet file.
struct FleetEntry {
  std::string name;     ///< 1-64 of [A-Za-z0-9_-]: it names the vehicle's output folder
  std::string dataset;  ///< folder, resolved against the fleet file's folder
};

/// True for a vehicle name of a fleet file: 1-64 of [A-Za-z0-9_-] (it names a folder, and over LCM
/// the prefix of the vehicle's channels, transport/channels.h).
bool isVehicleName(std::string_view name);

/// Reads a fleet file. Throws std::runtime_error "<path>[:line]: ..." naming the key for a missing
/// or unknown key, an empty list, a bad or repeated name.
std::vector<FleetEntry> loadFleetFile(const std::string& path);

}  // namespace meshnav
