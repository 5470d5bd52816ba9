#include <gtest/gtest.h>

#include "common/atmosphere.h"

using namespace meshnav::atmosphere;

TEST(Atmosphere, RoundTripAndKnownValues) {
  const double p_ref = 97000.0;
  for (double h : {-10.0, 0.0, 2.0, 8.0, 100.0}) {
    EXPECT_NEAR(heightFromPressure(pressureFromHeight(h, p_ref), p_ref), h, 1e-9);
  }
  EXPECT_DOUBLE_EQ(heightFromPressure(p_ref, p_ref), 0.0);
  // Standard atmosphere: 1000 m above sea level is 89874.6 Pa.
  EXPECT_NEAR(pressureFromHeight(1000.0, kSeaLevelPressure_Pa), 89874.6, 1.0);
  // Near the ground about 12 Pa per metre.
  EXPECT_NEAR(pressureFromHeight(0.0, p_ref) - pressureFromHeight(1.0, p_ref), 11.5, 0.6);
}

TEST(Atmosphere, DerivativeMatchesNumerical) {
  const double p_ref = 101325.0;
  for (double p : {95000.0, 100000.0, 101325.0}) {
    const double num = (heightFromPressure(p + 0.5, p_ref) - heightFromPressure(p - 0.5, p_ref)) / 1.0;
    EXPECT_NEAR(dHeightDPressure(p, p_ref), num, 1e-6);
  }
}
