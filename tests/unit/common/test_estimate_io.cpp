// Reading the estimator's outputs back (common/estimate_io.h): rows that cannot be what they claim.
#include <gtest/gtest.h>

#include "common/estimate_io.h"
#include "tests/support/test_util.h"

#include <cstdio>
#include <fstream>
#include <iterator>

using namespace meshnav;

// Found by fuzz target estimate_csv (UBSan: 1e+20 cast to int): an anchors.csv id that is not a
// device id is reported and its row skipped; the good row stays.
TEST(EstimateIo, AnchorIdsThatAreNotDeviceIdsAreSkipped) {
  const test::TempDir d("estimate_io");
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

// Found by fuzz target estimate_csv: a zero quaternion came back as a zero "rotation". A quaternion
// far from unit norm is reported and its row skipped, as in groundtruth.csv.
TEST(EstimateIo, QuaternionFarFromUnitIsSkipped) {
  const test::TempDir d("estimate_io_q");
  const std::string head = "t,tx,ty,tz,qx,qy,qz,qw,pxx,pxy,pxz,pyy,pyz,pzz,qrr,qrp,qry,qpp,qpy,qyy\n";
  const std::string cov = ",0.01,0,0,0.01,0,0.02,1e-4,0,0,1e-4,0,1e-4\n";
  const std::string path = test::writeFile(d / "estimate.csv", head + "0.5,1,2,3,0,0,0,0" + cov + "0.6,1,2,3,0,0,0,3" + cov +
                                                                   "0.7,1,2,3,0,0,0,1.05" + cov);
  Diagnostics diag;
  const auto e = readEstimateCsv(path, diag);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_DOUBLE_EQ(e[0].q_ItoG.norm(), 1.0);
  EXPECT_EQ(diag.get("estimate.csv:bad_quaternion"), 2);
}

// Issue 36: a run on a full disk ended with exit 0 and a torn estimate.csv. A write that fails
// is not silent: flush() throws naming the file (/dev/full fails every write with ENOSPC).
TEST(EstimateIo, AFailedWriteIsReportedByFlushNamingTheFile) {
  EstimateCsvWriter w("/dev/full");
  PoseEstimate e;
  e.t = Timestamp::fromSec(1.0);
  for (int i = 0; i < 100; ++i) w.write(e);
  try {
    w.flush();
    FAIL() << "flush on /dev/full did not throw";
  } catch (const std::runtime_error& ex) {
    EXPECT_NE(std::string(ex.what()).find("/dev/full: write failed"), std::string::npos) << ex.what();
    // Which rows: nothing was flushed, so all 100 (the bytes handed to the stream) are lost.
    EXPECT_NE(std::string(ex.what()).find("100 rows from its first row ("), std::string::npos) << ex.what();
  }
  AnchorsCsvWriter a("/dev/full");
  a.write(AnchorEstimate{});
  EXPECT_THROW(a.flush(), std::runtime_error);
}

// The message of a failed write counts the rows after the last flush that succeeded.
TEST(StreamTally, NamesTheRowsAfterTheLastGoodFlush) {
  StreamTally t;
  t.wrote("1.000000", 50);
  t.wrote("2.000000", 50);
  t.flushed();
  t.wrote("3.000000", 40);
  EXPECT_EQ(t.lost(), "the file is incomplete: 1 rows after t = 2.000000 s (40 bytes), written since the last flush "
                      "that succeeded, are lost or torn");
}

// A writer whose writes succeed flushes without a word, as often as asked.
TEST(EstimateIo, FlushOfAGoodFileDoesNotThrow) {
  const test::TempDir d("estimate_io_flush");
  EstimateCsvWriter w((d / "estimate.csv").string());
  PoseEstimate e;
  w.write(e);
  EXPECT_NO_THROW(w.flush());
  EXPECT_NO_THROW(w.flush());
}

namespace {
std::string fileText(const std::filesystem::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
}  // namespace

// The writers format with std::to_chars: each row as the former snprintf "%.9g" / "%.6g" wrote it,
// byte for byte, for values that are hard to print (estimate.csv of a run must not change).
TEST(EstimateIo, RowsAreWhatPrintfWrites) {
  const test::TempDir d("estimate_io_printf");
  const double tricky[] = {0.0, -0.0, 1.0, -1.5, 1e-300, 4.9e-324, 1.7976931348623157e308, 0.1, 123456789.5,
                           1234567895.0, 9.9999999949999, 2.5e-7, -3.0000000049e5, 1.0 / 3.0, 6.02214076e23};
  std::vector<PoseEstimate> poses;
  std::vector<AnchorEstimate> anchors;
  const int n = static_cast<int>(std::size(tricky));
  for (int k = 0; k < n; ++k) {
    auto v = [&](int i) { return tricky[(k + i) % n]; };
    PoseEstimate e;
    e.t = Timestamp{(k % 2 ? -1 : 1) * static_cast<int64_t>(k) * 1234567};
    e.p_IinG = {v(0), v(1), v(2)};
    e.q_ItoG.coeffs() << v(3), v(4), v(5), v(6);  // x, y, z, w: not a rotation, printed as given
    for (int i = 0; i < 9; ++i) e.cov_p_m2.data()[i] = v(7 + i);
    for (int i = 0; i < 9; ++i) e.cov_theta_rad2.data()[i] = v(16 + i);
    poses.push_back(e);
    AnchorEstimate a;
    a.t = e.t;
    a.id = 100 + k;
    a.p_AinG = e.p_IinG;
    a.cov_p_m2 = e.cov_theta_rad2;
    anchors.push_back(a);
  }
  {
    EstimateCsvWriter w((d / "estimate.csv").string());
    for (const auto& e : poses) w.write(e);
    w.flush();
    AnchorsCsvWriter wa((d / "anchors.csv").string());
    for (const auto& a : anchors) wa.write(a);
    wa.flush();
  }
  std::string expected_e = "t,tx,ty,tz,qx,qy,qz,qw,pxx,pxy,pxz,pyy,pyz,pzz,qrr,qrp,qry,qpp,qpy,qyy\n";
  std::string expected_a = "t,id,x,y,z,pxx,pxy,pxz,pyy,pyz,pzz\n";
  char buf[512];
  for (const auto& e : poses) {
    const auto& P = e.cov_p_m2;
    const auto& Q = e.cov_theta_rad2;
    std::snprintf(buf, sizeof(buf),
                  "%s,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n",
                  formatSeconds(e.t).c_str(), e.p_IinG.x(), e.p_IinG.y(), e.p_IinG.z(), e.q_ItoG.x(), e.q_ItoG.y(),
                  e.q_ItoG.z(), e.q_ItoG.w(), P(0, 0), P(0, 1), P(0, 2), P(1, 1), P(1, 2), P(2, 2), Q(0, 0), Q(0, 1),
                  Q(0, 2), Q(1, 1), Q(1, 2), Q(2, 2));
    expected_e += buf;
  }
  for (const auto& a : anchors) {
    const auto& P = a.cov_p_m2;
    std::snprintf(buf, sizeof(buf), "%s,%d,%.9g,%.9g,%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", formatSeconds(a.t).c_str(),
                  a.id, a.p_AinG.x(), a.p_AinG.y(), a.p_AinG.z(), P(0, 0), P(0, 1), P(0, 2), P(1, 1), P(1, 2),
                  P(2, 2));
    expected_a += buf;
  }
  EXPECT_EQ(fileText(d / "estimate.csv"), expected_e);
  EXPECT_EQ(fileText(d / "anchors.csv"), expected_a);
}
