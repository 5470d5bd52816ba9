/// writeFileAtomically (common/atomic_file.h): a file written once is the whole new text or the
/// old file untouched, and a failed write is an error naming the file (issue 36, item 1).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include "common/atomic_file.h"

using namespace meshnav;
namespace fs = std::filesystem;

namespace {
std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}
fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("meshnav_atomic_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}
}  // namespace

TEST(AtomicFile, WritesTheWholeTextAndLeavesNoTemporary) {
  const fs::path d = scratch("ok");
  const fs::path p = d / "sub" / "status.txt";  // the folder is created
  writeFileAtomically(p.string(), [](std::ostream& out) { out << "complete: true\n"; });
  EXPECT_EQ(slurp(p), "complete: true\n");
  EXPECT_FALSE(fs::exists(p.string() + ".tmp"));
  writeFileAtomically(p.string(), [](std::ostream& out) { out << "complete: false\n"; });  // replaced
  EXPECT_EQ(slurp(p), "complete: false\n");
  fs::remove_all(d);
}

TEST(AtomicFile, AFailedWriteNamesTheFileAndLeavesTheOldOneWhole) {
  // The temporary is a link to /dev/full: every write fails with ENOSPC, as on a full disk.
  const fs::path d = scratch("full");
  const fs::path p = d / "calibration.yaml";
  { std::ofstream(p) << "anchors: []\n"; }
  fs::create_symlink("/dev/full", p.string() + ".tmp");
  try {
    writeFileAtomically(p.string(), [](std::ostream& out) { out << std::string(1 << 20, 'x'); });
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(p.string() + ": write failed (No space left on device; nothing written)"), std::string::npos) << m;
  }
  EXPECT_EQ(slurp(p), "anchors: []\n") << "the old file is untouched";
  EXPECT_FALSE(fs::exists(fs::symlink_status(p.string() + ".tmp"))) << "the temporary is removed";
  fs::remove_all(d);
}
