/// @file test_fleet_bus.cpp
/// @brief Each vehicle's LCM bus of a fleet (transport/fleet_bus.h): the port per vehicle, the
/// group and options kept, and the URLs that cannot give a bus per vehicle refused.
#include <gtest/gtest.h>

#include <set>
#include <stdexcept>
#include <string>

#include "transport/fleet_bus.h"

namespace meshnav::transport {
namespace {

TEST(FleetBus, PerVehicleIsTheBasePortPlusOnePlusTheIndexWithGroupAndOptionsKept) {
  const std::string base = "udpm://239.255.76.67:7667?ttl=0";
  EXPECT_EQ(vehicleLcmUrl(FleetBus::kPerVehicle, base, 0), "udpm://239.255.76.67:7668?ttl=0");
  EXPECT_EQ(vehicleLcmUrl(FleetBus::kPerVehicle, base, 4), "udpm://239.255.76.67:7672?ttl=0");
  EXPECT_EQ(vehicleLcmUrl(FleetBus::kPerVehicle, "udpm://239.1.2.3:20000?ttl=1&recv_buf_size=65536", 1),
            "udpm://239.1.2.3:20002?ttl=1&recv_buf_size=65536");
  EXPECT_EQ(vehicleLcmUrl(FleetBus::kPerVehicle, "udpm://239.1.2.3:20000", 0), "udpm://239.1.2.3:20001");
  // No port: LCM's default 7667.
  EXPECT_EQ(vehicleLcmUrl(FleetBus::kPerVehicle, "udpm://239.255.76.67?ttl=0", 0), "udpm://239.255.76.67:7668?ttl=0");
  // No vehicle's bus is the base bus, and no two vehicles share one.
  std::set<std::string> urls = {base};
  for (size_t k = 0; k < 100; ++k) EXPECT_TRUE(urls.insert(vehicleLcmUrl(FleetBus::kPerVehicle, base, k)).second);
}

TEST(FleetBus, SharedIsTheBaseUrlForEveryVehicleWhateverItIs) {
  EXPECT_EQ(vehicleLcmUrl(FleetBus::kShared, "udpm://239.255.76.67:7667?ttl=0", 3), "udpm://239.255.76.67:7667?ttl=0");
  EXPECT_EQ(vehicleLcmUrl(FleetBus::kShared, "memq://", 0), "memq://");
}

TEST(FleetBus, RefusesUrlsWithoutABusPerVehicle) {
  EXPECT_THROW(vehicleLcmUrl(FleetBus::kPerVehicle, "memq://", 0), std::invalid_argument);
  EXPECT_THROW(vehicleLcmUrl(FleetBus::kPerVehicle, "udpm://239.255.76.67:76x7?ttl=0", 0), std::invalid_argument);
  EXPECT_THROW(vehicleLcmUrl(FleetBus::kPerVehicle, "udpm://239.255.76.67:?ttl=0", 0), std::invalid_argument);
  EXPECT_THROW(vehicleLcmUrl(FleetBus::kPerVehicle, "udpm://:7667", 0), std::invalid_argument);
  EXPECT_THROW(vehicleLcmUrl(FleetBus::kPerVehicle, "udpm://239.255.76.67:70000", 0), std::invalid_argument);
  EXPECT_EQ(vehicleLcmUrl(FleetBus::kPerVehicle, "udpm://239.255.76.67:65534", 0), "udpm://239.255.76.67:65535");
  EXPECT_THROW(vehicleLcmUrl(FleetBus::kPerVehicle, "udpm://239.255.76.67:65534", 1), std::invalid_argument);
}

TEST(FleetBus, NamesRoundTripAndAnUnknownOneIsRefused) {
  for (FleetBus b : {FleetBus::kShared, FleetBus::kPerVehicle}) EXPECT_EQ(parseFleetBus(toString(b)), b);
  EXPECT_THROW(parseFleetBus("per_vehicle"), std::invalid_argument);
}

}  // namespace
}  // namespace meshnav::transport
