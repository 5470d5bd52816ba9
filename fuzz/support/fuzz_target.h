#pragma once
/// @file fuzz_target.h
/// @brief What every fuzz target in fuzz/targets/ provides and may use.
///
/// A target defines libFuzzer's entry point `LLVMFuzzerTestOneInput`. It feeds the bytes to one
/// parser or decoder exactly as the program would receive them (a file, a line, an LCM message)
/// and treats two outcomes as fine: the input is accepted (and then what came out must satisfy
/// the parser's documented promises, checked with `require`), or the input is refused with a
/// `std::runtime_error` (the documented way to refuse a bad file or message). Everything else is
/// a finding: a crash, a sanitizer report, any other exception (`std::out_of_range` from
/// `map::at`, `std::invalid_argument`, `std::bad_alloc`, ...) or a broken promise; each aborts, so
/// libFuzzer and the replay driver (fuzz/support/replay_main.cpp) stop on it with the input.

#include <cstddef>
#include <cstdint>
#include <exception>
#include <stdexcept>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace meshnav::fuzz {

/// Prints "fuzz finding: <what>" to stderr and aborts (the input is the reproducer).
[[noreturn]] void fail(const std::string& what);

/// `fail(what)` unless `ok`: a promise of the parser that the accepted input broke.
inline void require(bool ok, const std::string& what) {
  if (!ok) fail(what);
}

/// Runs `body`; a `std::runtime_error` (bad input refused with a message) is fine, an empty
/// message is not (a refusal must say why), any other exception is a finding.
template <class Body>
void refusalsAllowed(Body&& body) {
  try {
    body();
  } catch (const std::runtime_error& e) {
    require(e.what() != nullptr && e.what()[0] != '\0', "input refused with an empty message");
  } catch (const std::exception& e) {
    fail(std::string("unexpected exception (not a refusal of bad input): ") + e.what());
  }
}

}  // namespace meshnav::fuzz
