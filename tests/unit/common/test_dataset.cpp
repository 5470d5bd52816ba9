#include <gtest/gtest.h>

#include "tests/support/shared_data.h"

#include <filesystem>

#include "common/dataset.h"
#include "common/estimate_io.h"
#include "tests/support/test_util.h"

using namespace meshnav;

TEST(Ranges, ReadsLettersAndAsciiTypeCodes) {
  const test::TempDir d("ranges");
  auto f = test::writeFile(d / "ranges.csv",
                           "t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,type_ID1,type_ID2,LOS\n"
                           "1.0,4.5,0.0,0.0,100,101,T,A,1\n"
                           "1.5,2.9,0.0,0.01,1,2,65,65,False\n");
  Diagnostics diag;
  auto r = readRangesCsv(f, diag);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].id_initiator, 100);
  EXPECT_EQ(r[0].type_initiator, UwbType::Tag);
  EXPECT_EQ(r[1].type_responder, UwbType::Anchor);
  EXPECT_EQ(r[1].t, Timestamp::fromSec(1.5));
  EXPECT_DOUBLE_EQ(r[1].R_m2, 0.01);
  EXPECT_FALSE(r[1].los);
  EXPECT_EQ(diag.total(), 0);
}

TEST(Ranges, BadRowsAreReportedCountedAndDropped) {
  const test::TempDir d("ranges");
  auto f = test::writeFile(d / "ranges.csv",
                           "t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,type_ID1,type_ID2,LOS\n"
                           "1.0,nan,0,0,100,101,T,A,1\n"       // NaN range
                           "1.1,-3.0,0,0,100,101,T,A,1\n"      // negative
                           "1.2,9999,0,0,100,101,T,A,1\n"      // absurd
                           "1.3,4.0,0,0,100,100,T,T,1\n"       // self range
                           "1.4,4.0,0,0,x,101,T,A,1\n"         // bad id
                           "1.5,4.0,0,0,100,101,Q,A,1\n"       // bad type
                           "abc,4.0,0,0,100,101,T,A,1\n"       // bad time
                           "1.7,4.0,0,0,100,101\n"             // short row
                           "1.8,4.0,0,0,100,101,T,A,1\n");     // good
  Diagnostics diag;
  auto r = readRangesCsv(f, diag);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_DOUBLE_EQ(r[0].range_m, 4.0);
  EXPECT_EQ(diag.get("ranges.csv:nan_range"), 1);
  EXPECT_EQ(diag.get("ranges.csv:negative_range"), 1);
  EXPECT_EQ(diag.get("ranges.csv:absurd_range"), 1);
  EXPECT_EQ(diag.get("ranges.csv:self_range"), 1);
  EXPECT_EQ(diag.get("ranges.csv:bad_id"), 1);
  EXPECT_EQ(diag.get("ranges.csv:bad_type"), 1);
  EXPECT_EQ(diag.get("ranges.csv:bad_time"), 1);
  EXPECT_EQ(diag.get("ranges.csv:bad_row"), 1);
}

TEST(Ranges, OptionalColumnsAreTheRawRangeWhenEmptyAndBadInputWhenNotNumbers) {
  const test::TempDir d("ranges");
  auto f = test::writeFile(d / "ranges.csv",
                           "t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,type_ID1,type_ID2,LOS\n"
                           "1.0,4.0,nan,0,100,101,T,A,1\n"      // range_corr not a number
                           "1.1,4.0,9999,0,100,101,T,A,1\n"     // range_corr absurd
                           "1.2,4.0,4.1,-1,100,101,T,A,1\n"     // negative variance
                           "1.3,4.0,4.1,inf,100,101,T,A,1\n"    // infinite variance
                           "1.4,4.0,4.1,1e6,100,101,T,A,1\n"    // beyond 500^2 m^2
                           "1.5,4.0,,,100,101,T,A,1\n"          // both empty: not given
                           "1.6,4.0,3.9,0.04,100,101,T,A,1\n"); // both given
  Diagnostics diag;
  auto r = readRangesCsv(f, diag);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_DOUBLE_EQ(r[0].range_corr_m, 4.0);  // the raw range, never 0 m
  EXPECT_DOUBLE_EQ(r[0].R_m2, 0.0);
  EXPECT_DOUBLE_EQ(r[1].range_corr_m, 3.9);
  EXPECT_DOUBLE_EQ(r[1].R_m2, 0.04);
  EXPECT_EQ(diag.get("ranges.csv:bad_range_corr"), 2);
  EXPECT_EQ(diag.get("ranges.csv:bad_R"), 3);
  // Without the optional columns at all.
  auto g = test::writeFile(d / "ranges2.csv", "t,range_raw,UWB_ID1,UWB_ID2,type_ID1,type_ID2\n2.0,5.5,100,101,T,A\n");
  Diagnostics diag2;
  auto r2 = readRangesCsv(g, diag2);
  ASSERT_EQ(r2.size(), 1u);
  EXPECT_DOUBLE_EQ(r2[0].range_corr_m, 5.5);
  EXPECT_DOUBLE_EQ(r2[0].R_m2, 0.0);
  EXPECT_EQ(diag2.total(), 0);
}

TEST(Ranges, TimeGoingBackwardsIsReportedAndSorted) {
  const test::TempDir d("ranges");
  auto f = test::writeFile(d / "ranges.csv",
                           "t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,type_ID1,type_ID2,LOS\n"
                           "2.0,1,0,0,100,101,T,A,1\n1.0,2,0,0,100,101,T,A,1\n3.0,3,0,0,100,101,T,A,1\n");
  Diagnostics diag;
  auto r = readRangesCsv(f, diag);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_DOUBLE_EQ(r[0].range_m, 2.0);
  EXPECT_EQ(diag.get("ranges.csv:time_backwards"), 1);
}

TEST(Ranges, ImportsTheRealRecording) {
  const std::string dir = std::string(MESHNAV_SHARED_DIR) + "/data/real-t1-a3-loiter";
  MESHNAV_REQUIRE_SHARED_DATA(dir);
  Diagnostics diag;
  size_t total = 0;
  for (const char* name : {"a01_ranges.csv", "a02_ranges.csv", "a03_ranges.csv", "d01_ranges.csv"}) {
    auto r = readRangesCsv(dir + "/" + name, diag);
    EXPECT_GT(r.size(), 1000u) << name;
    for (const auto& s : r) {
      EXPECT_GE(s.id_initiator, 0);
      EXPECT_LE(s.id_initiator, 3);
      EXPECT_GT(s.t.sec(), 1.69e9);
    }
    total += r.size();
  }
  // Every data row is either kept or counted as dropped (the recording has ~7 % gross outliers,
  // ranges of about ±338 km from corrupted TWR frames).
  EXPECT_EQ(static_cast<int64_t>(total) + diag.total(), 1735 + 1624 + 1532 + 1977);
  EXPECT_GT(diag.get("a01_ranges.csv:absurd_range") + diag.get("a01_ranges.csv:negative_range"), 0);
  EXPECT_LT(static_cast<double>(diag.total()) / static_cast<double>(total), 0.10);
}

TEST(Imu, BadValuesAreDropped) {
  const test::TempDir d("imu");
  auto f = test::writeFile(d / "imu.csv",
                           "t,lin_acc_x,lin_acc_y,lin_acc_z,ang_vel_x,ang_vel_y,ang_vel_z\n"
                           "0.000,0,0,9.81,0,0,0\n0.005,nan,0,9.81,0,0,0\n0.010,0,0,9000,0,0,0\n0.015,0,0,9.8,0,0,0.1\n");
  Diagnostics diag;
  auto v = readImuCsv(f, diag);
  ASSERT_EQ(v.size(), 2u);
  EXPECT_DOUBLE_EQ(v[1].gyro_rad_s.z(), 0.1);
  EXPECT_EQ(diag.get("imu.csv:bad_value"), 1);
  EXPECT_EQ(diag.get("imu.csv:absurd_value"), 1);
}

TEST(Dataset, WriteReadRoundTrip) {
  const test::TempDir d("ds");
  Dataset ds;
  ds.setup.rel_tag_positions[100] = {0.1, 0, 0};
  ds.setup.abs_anchor_positions[101] = {1, 2, 3};
  for (int i = 0; i < 10; ++i) {
    const Timestamp t = Timestamp::fromSec(0.005 * i);
    ds.imu.push_back({t, {0.1 * i, 0, 9.81}, {0, 0, 0.01 * i}});
    ds.baro.push_back({t, 97000.0 + i});
    ds.flight_states.push_back({t, i < 5});
    ds.ground_truth.push_back({t, {1.0 * i, 0, 0}, Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d::UnitZ()))});
    RangeSample r;
    r.t = t;
    r.id_initiator = 100;
    r.id_responder = 101;
    r.range_m = 3.0 + 0.01 * i;
    r.R_m2 = 0.01;
    ds.ranges.push_back(r);
  }
  ds.truth = Truth{};
  ds.truth->anchor_positions[101] = {1, 2, 3};
  writeDataset(ds, d.string());
  Diagnostics diag;
  auto r = readDataset(d.string(), diag, true);
  EXPECT_EQ(diag.total(), 0) << diag.summary();
  ASSERT_EQ(r.imu.size(), 10u);
  EXPECT_NEAR(r.imu[9].acc_m_s2.x(), 0.9, 1e-9);
  EXPECT_EQ(r.imu[9].t, ds.imu[9].t);
  EXPECT_NEAR(r.baro[3].pressure_pa, 97003.0, 1e-6);
  EXPECT_EQ(r.flight_states[4].landed, true);
  EXPECT_EQ(r.flight_states[5].landed, false);
  EXPECT_NEAR(r.ranges[7].range_m, 3.07, 1e-9);
  EXPECT_TRUE(r.ground_truth[5].q_ItoG.isApprox(ds.ground_truth[5].q_ItoG, 1e-8));
  ASSERT_TRUE(r.truth);
  EXPECT_TRUE(r.truth->anchor_positions.at(101).isApprox(Eigen::Vector3d(1, 2, 3)));
}

TEST(Dataset, MissingFolderOrRangesIsAClearError) {
  Diagnostics diag;
  EXPECT_THROW(readDataset("/nonexistent/dataset", diag), std::runtime_error);
  const test::TempDir d("ds");
  saveSetup(SystemSetup{}, (d / "setup.yaml").string());
  try {
    readDataset(d.string(), diag);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("ranges.csv"), std::string::npos);
  }
}

TEST(EstimateIo, RoundTripAndAutoDetection) {
  const test::TempDir d("est");
  {
    EstimateCsvWriter w((d / "estimate.csv").string());
    PoseEstimate e;
    e.t = Timestamp::fromSec(1.25);
    e.p_IinG = {1, 2, 3};
    e.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()));
    e.cov_p_m2 << 1, 0.1, 0.2, 0.1, 2, 0.3, 0.2, 0.3, 3;
    e.cov_theta_rad2 = Eigen::Matrix3d::Identity() * 1e-4;
    w.write(e);
    AnchorsCsvWriter a((d / "anchors.csv").string());
    a.write({Timestamp::fromSec(2.0), 106, {1, 2, 3}, Eigen::Matrix3d::Identity() * 0.09});
  }
  Diagnostics diag;
  auto e = readEstimateCsv((d / "estimate.csv").string(), diag);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_DOUBLE_EQ(e[0].cov_p_m2(2, 1), 0.3);
  EXPECT_DOUBLE_EQ(e[0].cov_p_m2(1, 2), 0.3);
  EXPECT_TRUE(e[0].q_ItoG.isApprox(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX())), 1e-8));
  auto poses = readPosesAuto((d / "estimate.csv").string(), diag);
  ASSERT_EQ(poses.size(), 1u);
  EXPECT_TRUE(poses[0].p_IinG.isApprox(Eigen::Vector3d(1, 2, 3)));
  auto a = readAnchorsCsv((d / "anchors.csv").string(), diag);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].id, 106);
  EXPECT_DOUBLE_EQ(a[0].cov_p_m2(1, 1), 0.09);
  EXPECT_EQ(diag.total(), 0);
}

TEST(Height, OptionalFileIsReadValidatedAndWrittenBack) {
  const test::TempDir d("height");
  test::writeFile(d / "setup.yaml", "imu_id: 1\n");
  test::writeFile(d / "ranges.csv", "t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,type_ID1,type_ID2,LOS\n");
  Diagnostics diag;
  EXPECT_TRUE(readDataset(d.string(), diag).heights.empty());  // optional: absent is fine
  test::writeFile(d / "height.csv",
                  "t,range_m\n0.103620767,0.29\n0.136620759,0.31\n0.2,nan\n0.3,-1\n0.4,250\n");
  auto ds = readDataset(d.string(), diag);
  ASSERT_EQ(ds.heights.size(), 2u);
  EXPECT_EQ(ds.heights[0].t.us, 103621);
  EXPECT_DOUBLE_EQ(ds.heights[1].range_m, 0.31);
  EXPECT_EQ(diag.get("height.csv:bad_value"), 3);
  const test::TempDir out("height_out");
  writeDataset(ds, out.string());
  Diagnostics diag2;
  const auto back = readHeightCsv((out / "height.csv").string(), diag2);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1].t, ds.heights[1].t);
  EXPECT_DOUBLE_EQ(back[1].range_m, 0.31);
  EXPECT_EQ(diag2.total(), 0);
}
