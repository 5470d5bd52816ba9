// DirLock (common/dir_lock.h): one process per output folder. flock locks belong to an open file
// description, so a second claim from this same process stands for a second process.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <optional>

#include "common/dir_lock.h"
#include "tests/support/test_util.h"

using meshnav::DirLock;
using meshnav::DirLockError;

TEST(DirLock, ASecondClaimOnAFolderIsRefusedNamingItAndTheHolder) {
  const meshnav::test::TempDir d("dir_lock");
  const std::string dir = (d / "out").string();
  std::optional<DirLock> first;
  first.emplace(dir, "--out");  // creates the folder
  EXPECT_TRUE(std::filesystem::is_directory(dir));
  try {
    DirLock second(dir, "--out");
    FAIL() << "a second claim was granted";
  } catch (const DirLockError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("--out " + dir + " is in use by another process (pid "), std::string::npos) << m;
  }
  first.reset();  // released (as when the holder dies, kill -9 included: the kernel drops it)
  EXPECT_NO_THROW(DirLock again(dir, "--out"));
}

TEST(DirLock, OtherFoldersAreIndependent) {
  const meshnav::test::TempDir d("dir_lock_two");
  const DirLock a((d / "a").string(), "--state-dir");
  EXPECT_NO_THROW(DirLock b((d / "b").string(), "--state-dir"));
}
