#include <gtest/gtest.h>

#include "common/cli.h"

using namespace meshnav;

TEST(Cli, ParsesValuesFlagsAndRejectsUnknown) {
  Cli cli("prog", "usage: prog");
  cli.option("seed").option("fast", false);
  const char* argv[] = {"prog", "--seed", "7", "--fast", "pos"};
  int code = -1;
  ASSERT_TRUE(cli.parse(5, const_cast<char**>(argv), code));
  EXPECT_EQ(cli.getInt("seed", 0), 7);
  EXPECT_TRUE(cli.has("fast"));
  EXPECT_EQ(cli.positional().size(), 1u);

  Cli c2("prog", "usage");
  const char* bad[] = {"prog", "--nope"};
  EXPECT_FALSE(c2.parse(2, const_cast<char**>(bad), code));
  EXPECT_EQ(code, 2);

  Cli c3("prog", "usage");
  const char* help[] = {"prog", "--help"};
  EXPECT_FALSE(c3.parse(2, const_cast<char**>(help), code));
  EXPECT_EQ(code, 0);

  Cli c4("prog", "usage");
  c4.option("rate");
  const char* nonum[] = {"prog", "--rate=abc"};
  ASSERT_TRUE(c4.parse(2, const_cast<char**>(nonum), code));
  EXPECT_THROW(c4.getDouble("rate", 1.0), std::runtime_error);

  // Values that are numbers but not usable ones (issue 12, bad configuration).
  Cli c5("prog", "usage");
  c5.option("rate").option("count");
  const char* unusable[] = {"prog", "--rate=inf", "--count=99999999999999999999"};
  ASSERT_TRUE(c5.parse(3, const_cast<char**>(unusable), code));
  EXPECT_THROW(c5.getDouble("rate", 1.0), std::runtime_error);
  EXPECT_THROW(c5.getInt("count", 1), std::runtime_error);
}
