// Import of range CSV files in the published format: the real recording (one file per device,
// type columns as ASCII codes 65/84), merged and time-sorted; and small files written here.
#include <gtest/gtest.h>

#include "tests/support/shared_data.h"
#include "tests/support/test_util.h"

#include <filesystem>
#include <fstream>
#include <set>

#include "uwb_bridge/range_csv_import.h"

using namespace meshnav;
using namespace meshnav::uwb;
namespace fs = std::filesystem;

namespace {

const fs::path kReal = fs::path(MESHNAV_SHARED_DIR) / "data" / "real-t1-a3-loiter";

int64_t dataRows(const fs::path& p) {
  std::ifstream in(p);
  std::string line;
  int64_t n = -1;  // header
  while (std::getline(in, line))
    if (!line.empty()) ++n;
  return n;
}

fs::path writeFile(const std::string& name, const std::string& content) {
  static const meshnav::test::TempDir dir("uwb");  // removed at exit
  const fs::path p = dir / name;
  std::ofstream(p) << content;
  return p;
}

}  // namespace

TEST(RangeCsvImport, RealRecordingMergesFourDevices) {
  MESHNAV_REQUIRE_SHARED_DATA(kReal / "d01_ranges.csv");
  std::vector<std::string> files;
  int64_t rows = 0;
  for (const char* f : {"a01_ranges.csv", "a02_ranges.csv", "a03_ranges.csv", "d01_ranges.csv"}) {
    files.push_back((kReal / f).string());
    rows += dataRows(kReal / f);
  }
  EXPECT_EQ(rows, 1735 + 1624 + 1532 + 1977);
  Diagnostics diag;
  const auto ranges = importRangeCsv(files, diag);
  // Every row is either imported or reported (the recording has firmware garbage like -316918 m).
  int64_t dropped = 0;
  for (const auto& [kind, n] : diag.snapshot())
    if (kind.find("time_backwards") == std::string::npos) dropped += n;
  EXPECT_EQ(static_cast<int64_t>(ranges.size()) + dropped, rows);
  EXPECT_GT(ranges.size(), 6000u);
  EXPECT_GT(diag.get("a01_ranges.csv:negative_range"), 0);
  std::set<SensorId> ids;
  std::map<SensorId, int64_t> initiated;
  for (size_t i = 0; i < ranges.size(); ++i) {
    const auto& r = ranges[i];
    if (i) {
      ASSERT_LE(ranges[i - 1].t, r.t) << "not time-sorted at " << i;
    }
    ids.insert(r.id_initiator);
    ids.insert(r.id_responder);
    ++initiated[r.id_initiator];
    // Device 0 is the tag (type 84), 1..3 anchors (65).
    EXPECT_EQ(r.type_initiator, r.id_initiator == 0 ? UwbType::Tag : UwbType::Anchor);
    EXPECT_EQ(r.type_responder, r.id_responder == 0 ? UwbType::Tag : UwbType::Anchor);
    EXPECT_GE(r.range_m, -0.5);
    EXPECT_LE(r.range_m, 500.0);
  }
  EXPECT_EQ(ids, (std::set<SensorId>{0, 1, 2, 3}));
  EXPECT_EQ(initiated.size(), 4u);  // each file holds the ranges its device initiated
  EXPECT_NEAR(ranges.front().t.sec(), 1693508300.5975, 1e-3);
  EXPECT_NEAR((ranges.back().t - ranges.front().t).sec(), 74.1, 0.1);
}

TEST(RangeCsvImport, LettersAndCodesMergedStably) {
  const auto a = writeFile("a.csv",
                           "t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,type_ID1,type_ID2,LOS\n"
                           "0.30,3.0,0.0,0.0,101,100,A,T,1\n"
                           "0.10,1.0,0.0,0.0,101,102,65,65,True\n"
                           "0.20,nan,0.0,0.0,101,100,65,84,False\n");
  const auto b = writeFile("b.csv",
                           "t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,type_ID1,type_ID2,LOS\n"
                           "0.10,2.0,1.9,0.01,100,101,84,65,0\n"
                           "0.25,2.5,0.0,0.0,100,101,X,65,0\n");
  Diagnostics diag;
  const auto r = importRangeCsv({a.string(), b.string()}, diag);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_DOUBLE_EQ(r[0].range_m, 1.0);  // equal times: file order kept
  EXPECT_DOUBLE_EQ(r[1].range_m, 2.0);
  EXPECT_EQ(r[1].type_initiator, UwbType::Tag);
  EXPECT_DOUBLE_EQ(r[1].range_corr_m, 1.9);
  EXPECT_DOUBLE_EQ(r[1].R_m2, 0.01);
  EXPECT_FALSE(r[1].los);
  EXPECT_DOUBLE_EQ(r[2].range_m, 3.0);
  EXPECT_EQ(diag.total(), 3);  // nan range, unknown type, time going backwards in a.csv
  fs::remove(a);
  fs::remove(b);
}

TEST(RangeCsvImport, MissingFileThrows) {
  Diagnostics diag;
  EXPECT_THROW(importRangeCsv({"/nonexistent/ranges.csv"}, diag), std::runtime_error);
}

TEST(RangeCsvImport, SplitPathList) {
  EXPECT_EQ(splitPathList("a.csv, b.csv,,c.csv "), (std::vector<std::string>{"a.csv", "b.csv", "c.csv"}));
  EXPECT_TRUE(splitPathList("").empty());
}

// A multi-host deployment runs one bridge per anchor computer, each publishing the ranges its
// anchor initiated (--initiators): together the bridges publish every range exactly once.
TEST(RangeCsvImport, KeepInitiatorsSplitsRangesPerInitiatingDevice) {
  const auto p = writeFile("initiators.csv",
                           "t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,type_ID1,type_ID2,LOS\n"
                           "1.0,3.0,3.0,0.01,101,100,A,T,1\n"
                           "1.1,4.0,4.0,0.01,100,102,T,A,1\n"
                           "1.2,5.0,5.0,0.01,102,101,A,A,1\n"
                           "1.3,6.0,6.0,0.01,101,102,A,A,1\n");
  Diagnostics diag;
  const auto all = importRangeCsv({p.string()}, diag);
  ASSERT_EQ(all.size(), 4u);

  auto a101 = all;
  EXPECT_EQ(keepInitiators(a101, {101}), 2u);
  ASSERT_EQ(a101.size(), 2u);
  EXPECT_DOUBLE_EQ(a101[0].range_m, 3.0);
  EXPECT_DOUBLE_EQ(a101[1].range_m, 6.0);  // order kept

  auto rest = all;
  EXPECT_EQ(keepInitiators(rest, {100, 102}), 2u);
  ASSERT_EQ(rest.size(), 2u);
  EXPECT_EQ(rest[0].id_initiator, 100);
  EXPECT_EQ(rest[1].id_initiator, 102);

  auto none = all;
  EXPECT_EQ(keepInitiators(none, {}), 0u);  // no filter: everything
  EXPECT_EQ(none.size(), 4u);
  auto unknown = all;
  EXPECT_EQ(keepInitiators(unknown, {999}), 4u);
  EXPECT_TRUE(unknown.empty());
  fs::remove(p);
}
