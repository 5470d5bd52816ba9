#pragma once
/// @file shared_data.h
/// @brief Tests on the real recordings in ../shared/data: without them a user's run skips with a
/// visible reason; CI always has them, so there (environment variable CI set) a missing file fails.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

/// In a test body: skip (or, under CI, fail) unless `path` exists.
#define MESHNAV_REQUIRE_SHARED_DATA(path)                                                                   \
  do {                                                                                                     \
    if (!std::filesystem::exists(path)) {                                                                  \
      if (std::getenv("CI")) FAIL() << "CI is set but the shared recording is missing: " << (path);        \
      GTEST_SKIP() << "shared recording not present (../shared/data): " << (path);                         \
    }                                                                                                      \
  } while (0)
