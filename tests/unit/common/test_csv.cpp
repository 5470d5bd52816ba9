#include <gtest/gtest.h>

#include "common/csv.h"
#include "tests/support/test_util.h"

using namespace meshnav;

TEST(Csv, ReadsColumnsByNameAndSkipsCommentsAndBlankLines) {
  const test::TempDir d("csv");
  auto f = test::writeFile(d / "a.csv", "b,a\n1,2\n\n# comment\n3,4\n");
  CsvReader r(f, {"a", "b"});
  Diagnostics diag;
  std::vector<std::pair<double, double>> rows;
  std::vector<int> lines;
  r.forEach([&](const CsvRow& row) {
    rows.emplace_back(*row.number("a"), *row.number("b"));
    lines.push_back(row.line());
  }, diag);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0], std::make_pair(2.0, 1.0));
  EXPECT_EQ(rows[1], std::make_pair(4.0, 3.0));
  EXPECT_EQ(lines, (std::vector<int>{2, 5}));
  EXPECT_EQ(diag.total(), 0);
}

TEST(Csv, MissingFileNamesThePath) {
  try {
    CsvReader r("/nonexistent/x.csv", {"t"});
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/x.csv"), std::string::npos);
  }
}

TEST(Csv, MissingColumnNamesFileAndColumn) {
  const test::TempDir d("csv");
  auto f = test::writeFile(d / "a.csv", "t,x\n1,2\n");
  try {
    CsvReader r(f, {"t", "pressure"});
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("a.csv:1"), std::string::npos) << m;
    EXPECT_NE(m.find("pressure"), std::string::npos) << m;
  }
}

TEST(Csv, EmptyFileIsAnError) {
  const test::TempDir d("csv");
  auto f = test::writeFile(d / "empty.csv", "");
  EXPECT_THROW(CsvReader(f, {}), std::runtime_error);
}

TEST(Csv, WrongFieldCountIsCountedAndSkipped) {
  const test::TempDir d("csv");
  auto f = test::writeFile(d / "a.csv", "t,x\n1,2\n3\n4,5,6\n7,8\n");
  CsvReader r(f, {"t", "x"});
  Diagnostics diag;
  int n = 0;
  r.forEach([&](const CsvRow&) { ++n; }, diag);
  EXPECT_EQ(n, 2);
  EXPECT_EQ(diag.get("a.csv:bad_row"), 2);
}

TEST(Csv, NonFiniteNumbersAreNullopt) {
  const test::TempDir d("csv");
  auto f = test::writeFile(d / "a.csv", "x,y,z\nnan,inf,abc\n");
  CsvReader r(f, {"x"});
  Diagnostics diag;
  r.forEach([&](const CsvRow& row) {
    EXPECT_FALSE(row.number("x"));
    EXPECT_FALSE(row.number("y"));
    EXPECT_FALSE(row.number("z"));
    EXPECT_FALSE(row.number("missing"));
  }, diag);
}

TEST(Csv, TumHeaderWithHashAndSpaces) {
  const test::TempDir d("csv");
  auto f = test::writeFile(d / "gt.txt", "#t tx ty\n1.5 2 3\n");
  CsvReader r(f, {"t", "tx", "ty"});
  Diagnostics diag;
  int n = 0;
  r.forEach([&](const CsvRow& row) {
    EXPECT_DOUBLE_EQ(*row.number("t"), 1.5);
    EXPECT_DOUBLE_EQ(*row.number("ty"), 3.0);
    ++n;
  }, diag);
  EXPECT_EQ(n, 1);
}

TEST(Csv, FilesAboveTheSizeLimitAreRefusedWithAMessage) {
  // Issue 12, finding 5: a 100 MB ranges.csv took 665 MB. Above maxCsvBytes() a file is refused
  // up front. The limit is lowered to 1 MiB here so that the test file stays small.
  ASSERT_EQ(setenv("MESHNAV_MAX_CSV_MB", "1", 1), 0);
  EXPECT_EQ(maxCsvBytes(), 1u << 20);
  const test::TempDir d("csv");
  std::string text = "t,range_raw,UWB_ID1,UWB_ID2,type_ID1,type_ID2\n";
  while (text.size() <= (1u << 20)) text += "1.000000,4.000000,100,101,T,A\n";
  const auto f = test::writeFile(d / "ranges.csv", text);
  try {
    CsvReader r(f, {"t"});
    ADD_FAILURE() << "a file above the limit was accepted";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(f + ": 1 MiB is more than the 1 MiB"), std::string::npos) << what;
    EXPECT_NE(what.find("MESHNAV_MAX_CSV_MB"), std::string::npos) << what;
  }
  ASSERT_EQ(setenv("MESHNAV_MAX_CSV_MB", "2", 1), 0);
  EXPECT_NO_THROW(CsvReader(f, {"t"}));
  ASSERT_EQ(unsetenv("MESHNAV_MAX_CSV_MB"), 0);
  EXPECT_EQ(maxCsvBytes(), 64u << 20);
}

TEST(Csv, ALimitThatIsNotANumberIsRefusedNotIgnored) {
  // Issue 36: MESHNAV_MAX_CSV_MB=2GB used to leave the 64 MiB default without a word.
  for (const char* bad : {"2GB", "-5", "0", "1.5", "huge"}) {
    ASSERT_EQ(setenv("MESHNAV_MAX_CSV_MB", bad, 1), 0);
    try {
      maxCsvBytes();
      ADD_FAILURE() << bad << " was taken as a limit";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("MESHNAV_MAX_CSV_MB='") + bad + "' is not a limit"),
                std::string::npos)
          << e.what();
    }
  }
  ASSERT_EQ(unsetenv("MESHNAV_MAX_CSV_MB"), 0);
}

TEST(Csv, AByteOrderMarkBeforeTheHeaderIsNotPartOfTheFirstColumn) {
  // Issue 36: a spreadsheet's UTF-8 export gave "missing column 't'" with the invisible mark in it.
  const test::TempDir d("csv");
  const auto f = test::writeFile(d / "imu.csv", "\xEF\xBB\xBFt,x\n1.5,2\n");
  CsvReader r(f, {"t", "x"});
  Diagnostics diag;
  int n = 0;
  r.forEach([&](const CsvRow& row) {
    EXPECT_DOUBLE_EQ(*row.number("t"), 1.5);
    ++n;
  }, diag);
  EXPECT_EQ(n, 1);
  EXPECT_EQ(diag.total(), 0);
}

// Fields are the pieces between commas, trimmed, empty ones included (after a trailing comma too):
// an empty field is no number, and a row with a trailing comma has one field more.
TEST(Csv, EmptyAndTrailingFieldsArePieces) {
  const test::TempDir d("csv_pieces");
  auto f = test::writeFile(d / "a.csv", "a,b,c\n 1 ,\t2,\n,,3\n4,5,6,\n7,8\n");
  CsvReader r(f, {"a", "b", "c"});
  Diagnostics diag;
  std::vector<std::string> rows;
  r.forEach([&](const CsvRow& row) {
    auto show = [&](const char* c) { return row.number(c) ? std::to_string(static_cast<int>(*row.number(c))) : "-"; };
    rows.push_back(show("a") + show("b") + show("c") + "|" + row.text("a"));
  }, diag);
  EXPECT_EQ(rows, (std::vector<std::string>{"12-|1", "--3|"}));
  EXPECT_EQ(diag.get("a.csv:bad_row"), 2);  // 4 fields, then 2
}
