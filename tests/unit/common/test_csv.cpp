#include <gtest/gtest.h>

#include "common/csv.h"
#include "test_util.h"

using namespace meshnav;

TEST(Csv, ReadsColumnsByNameAndSkipsCommentsAndBlankLines) {
  auto d = test::tempDir("csv");
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
  auto d = test::tempDir("csv");
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
  auto d = test::tempDir("csv");
  auto f = test::writeFile(d / "empty.csv", "");
  EXPECT_THROW(CsvReader(f, {}), std::runtime_error);
}

TEST(Csv, WrongFieldCountIsCountedAndSkipped) {
  auto d = test::tempDir("csv");
  auto f = test::writeFile(d / "a.csv", "t,x\n1,2\n3\n4,5,6\n7,8\n");
  CsvReader r(f, {"t", "x"});
  Diagnostics diag;
  int n = 0;
  r.forEach([&](const CsvRow&) { ++n; }, diag);
  EXPECT_EQ(n, 2);
  EXPECT_EQ(diag.get("a.csv:bad_row"), 2);
}

TEST(Csv, NonFiniteNumbersAreNullopt) {
  auto d = test::tempDir("csv");
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
  auto d = test::tempDir("csv");
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
