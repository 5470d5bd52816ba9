/// Tests of meshnav::Cli (common/cli.h): values bound to variables, --help built from the
/// declarations with the defaults of the code, refusals (unknown option, bad number, NaN, an id
/// that does not fit 32 bits) with exit 2 and the option named, and the `--config` options file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/cli.h"
#include "tests/support/test_util.h"

using namespace meshnav;

namespace {

std::string tempFile(const std::string& name, const std::string& text) {
  static const test::TempDir dir("test_cli");  // removed at exit
  return test::writeFile(dir / name, text);
}

/// A command with one option of each kind.
struct Fixture {
  Cli cli{"prog", "Does things."};
  double rate = 1.5;
  int64_t seed = 1;
  bool fast = false;
  std::string name;
  std::vector<int32_t> ids;
  Fixture() {
    cli.option("rate", rate, "playback speed")->type_name("N")->check(cli::nonNegative());
    cli.option("seed", seed, "seed");
    cli.flag("fast", fast, "go fast");
    cli.optional("name", name, "a name");
    cli.idList("anchors", ids, "anchor ids");
  }
  bool parse(const std::vector<std::string>& args, int& code) { return cli.parse(args, code); }
};

}  // namespace

TEST(Cli, ParsesValuesAndFlags) {
  Fixture f;
  int code = -1;
  ASSERT_TRUE(f.parse({"--rate", "2.5", "--seed=7", "--fast", "--name", "x", "--anchors", "106,107"}, code));
  EXPECT_EQ(code, 0);
  EXPECT_DOUBLE_EQ(f.rate, 2.5);
  EXPECT_EQ(f.seed, 7);
  EXPECT_TRUE(f.fast);
  EXPECT_EQ(f.name, "x");
  EXPECT_EQ(f.ids, (std::vector<int32_t>{106, 107}));
  EXPECT_TRUE(f.cli.given("rate"));
  EXPECT_FALSE(Fixture().cli.given("rate"));
}

TEST(Cli, HelpShowsTheDefaultsOfTheCode) {
  Fixture f;
  const std::string help = f.cli.help();
  EXPECT_NE(help.find("Does things."), std::string::npos) << help;
  EXPECT_NE(help.find("--rate N"), std::string::npos) << help;
  EXPECT_NE(help.find("playback speed; >= 0 (default 1.5)"), std::string::npos) << help;
  EXPECT_NE(help.find("--fast"), std::string::npos) << help;
  int code = -1;
  EXPECT_FALSE(f.parse({"--help"}, code));
  EXPECT_EQ(code, 0);
}

TEST(Cli, RefusesBadCommandLinesNamingTheOption) {
  for (const auto& [args, named] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"--nope"}, "--nope"},
           {{"--rate", "abc"}, "--rate"},
           {{"--rate", "nan"}, "--rate"},
           {{"--rate", "-1"}, "--rate"},
           {{"--seed", "1.5"}, "--seed"},
           {{"--anchors", "4294967297"}, "--anchors"},  // would be anchor 1 after a cut to 32 bits
           {{"--anchors", "106,x"}, "--anchors"},
           {{"--anchors", "-3"}, "--anchors"},
           {{"stray"}, "stray"}}) {
    Fixture f;
    int code = -1;
    EXPECT_FALSE(f.parse(args, code)) << args[0];
    EXPECT_EQ(code, 2) << args[0];
    EXPECT_NE(f.cli.error().find(named), std::string::npos) << f.cli.error();
  }
  Fixture f;
  int code = -1;
  ASSERT_FALSE(f.parse({"--anchors", "4294967297"}, code));
  EXPECT_NE(f.cli.error().find("4294967297"), std::string::npos) << f.cli.error();
  EXPECT_TRUE(f.ids.empty());
}

TEST(Cli, OptionsFileFillsWhatTheCommandLineDoesNotGive) {
  const std::string file = tempFile("ok.yaml", "rate: 4\nfast: true\nname: from_file\n");
  Fixture f;
  f.cli.optionsFile("options");
  int code = -1;
  ASSERT_TRUE(f.parse({"--config", file, "--name", "cli"}, code)) << f.cli.error();
  EXPECT_DOUBLE_EQ(f.rate, 4.0);
  EXPECT_TRUE(f.fast);
  EXPECT_EQ(f.name, "cli");  // the command line wins
  EXPECT_TRUE(f.cli.given("rate"));
  std::filesystem::remove(file);
}

TEST(Cli, OptionsFileErrorsNameFileAndKey) {
  for (const auto& [text, key] : std::vector<std::pair<std::string, std::string>>{
           {"rate: 4\nmax_rat: 5\n", "unknown option 'max_rat'"},  // unknown key, as written
           {"rate: [1, 2]\n", "rate"},               // not a single value
           {"rate: -2\n", "rate"},                   // out of range
           {"config: other.yaml\n", "config"}}) {  // no nesting
    const std::string file = tempFile("bad.yaml", text);
    Fixture f;
    f.cli.optionsFile("options");
    int code = -1;
    EXPECT_FALSE(f.parse({"--config", file}, code)) << text;
    EXPECT_EQ(code, 2);
    EXPECT_NE(f.cli.error().find(key), std::string::npos) << f.cli.error();
    if (key != "rate" || text.find('[') != std::string::npos) {  // a value out of range names the option only
      EXPECT_NE(f.cli.error().find(file), std::string::npos) << f.cli.error();
    }
    std::filesystem::remove(file);
  }
}
