// Reading the estimator's outputs back (common/estimate_io.h): rows that cannot be what they claim.
#include <gtest/gtest.h>

#include "common/estimate_io.h"
#include "test_util.h"

using namespace meshnav;

// Found by fuzz target estimate_csv (UBSan: 1e+20 cast to int): an anchors.csv id that is not a
// device id is reported and its row skipped; the good row stays.
TEST(EstimateIo, AnchorIdsThatAreNotDeviceIdsAreSkipped) {
  const auto d = test::tempDir("estimate_io");
  const std::string path = test::writeFile(d / "anchors.csv",
                                           "t,id,x,y,z,pxx,pxy,pxz,pyy,pyz,pzz\n"
                                           "1,1e20,1,2,3,1,0,0,1,0,1\n"
                                           "1,-4,1,2,3,1,0,0,1,0,1\n"
                                           "1,106.5,1,2,3,1,0,0,1,0,1\n"
                                           "2,2147483647,1,2,3,1,0,0,1,0,1\n");
  Diagnostics diag;
  const auto a = readAnchorsCsv(path, diag);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].id, 2147483647);
  EXPECT_EQ(diag.get("anchors.csv:bad_id"), 3);
}
