#pragma once
/// @file fleet.h
/// @brief Several vehicles sharing one anchor map (`meshnav_run --fleet FILE`, docs/fleet.md): the
/// fleet file, the setups merged into one anchor map, and the inputs of every vehicle in one time
/// order. Free of LCM, like the rest of the pipeline.
///
/// Fleet file (YAML; unknown keys and bad values are refused with the file and the key):
/// ```yaml
/// vehicles:                 # one entry per vehicle, at least one
///   - name: ifo001          # output subfolder and log name: letters, digits, '_' and '-'
///     dataset: ifo001       # dataset folder (docs/formats.md), relative to the fleet file
/// ```

#include <string>
#include <vector>

#include "common/fleet_file.h"
#include "common/setup.h"
#include "common/types.h"
#include "estimator/node/estimator_input.h"
#include "pipeline/pipeline.h"

namespace meshnav::pipeline {

/// The fleet file (common/fleet_file.h), also read by meshnav eval --fleet.
using meshnav::FleetEntry;
using meshnav::loadFleetFile;

/// The vehicles of fleet file `path` with the setup.yaml of each one's dataset (what a process
/// serving the fleet over LCM knows of it: the calibrator's and the peer_router's --fleet).
/// Throws as loadFleetFile and loadSetup, naming the file.
std::vector<Vehicle> loadFleetVehicles(const std::string& path);

/// Makes the vehicles' anchors one map and returns what the fleet's calibrator knows: every
/// vehicle's tags (with their lever arms) and the union of the known anchors, their σ and the pair
/// biases of the setups. Each vehicle's setup gets the union too, so that every estimator knows
/// every shared anchor. Throws std::invalid_argument (messages start with `where`) when
///  - a tag id belongs to two vehicles, or is another vehicle's anchor, IMU or baro id,
///  - a known anchor has different positions (more than 1 mm apart) or σ in two setups,
///  - a pair bias is given differently in two setups.
/// The other fields of the returned setup (IMU and baro ids, noise figures) are the first vehicle's.
SystemSetup mergeFleetSetups(std::vector<Vehicle>& vehicles, const std::string& where);

/// `a` as vehicle `vehicle` may fuse it: without the pair biases whose peer is a tag of `fleet`
/// that is not one of `vehicle`'s tags, and without their rows and columns of the joint
/// covariance. Unchanged when every peer is an anchor or one of the vehicle's tags.
AnchorInit restrictToVehicle(const AnchorInit& a, const SystemSetup& vehicle, const SystemSetup& fleet);

/// One input of one vehicle.
struct FleetInput {
  size_t vehicle = 0;
  estimator::EstimatorInput input;
};

/// Every vehicle's inputs (each in its canonical order, `mergeInTimeOrder`) in one time order;
/// at equal times the lower vehicle index first, and within a vehicle its own order.
std::vector<FleetInput> mergeFleetInputs(const std::vector<std::vector<estimator::EstimatorInput>>& per_vehicle);

}  // namespace meshnav::pipeline
