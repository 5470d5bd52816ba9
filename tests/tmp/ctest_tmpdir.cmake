# Read by ctest before it starts any test (a TEST_INCLUDE_FILES entry of the top directory, set in
# tests/CMakeLists.txt; MESHNAV_TEST_TMP_ROOT is <build>/test-tmp). Makes a fresh folder for this
# ctest run and gives it to every test as TMPDIR: std::filesystem::temp_directory_path(), gtest's
# TempDir(), Python's tempfile and mktemp all write there. After the last test, ctest runs
# tests/tmp/check_leftovers.sh (CTestCustom.cmake), which fails the run when anything is left in it.
# The microsecond stamp and the random suffix keep two ctest runs of one build folder apart.
string(TIMESTAMP _meshnav_stamp "%Y%m%d-%H%M%S-%f" UTC)
string(RANDOM LENGTH 6 _meshnav_rand)
set(_meshnav_tmp "${MESHNAV_TEST_TMP_ROOT}/run-${_meshnav_stamp}-${_meshnav_rand}")
file(MAKE_DIRECTORY "${_meshnav_tmp}")
set(ENV{TMPDIR} "${_meshnav_tmp}")
set(ENV{MESHNAV_TEST_TMPDIR} "${_meshnav_tmp}")  # what the check compares TMPDIR with
