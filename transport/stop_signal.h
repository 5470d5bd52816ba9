#pragma once
/// @file stop_signal.h
/// @brief Process-wide stop request set by SIGINT / SIGTERM (async-signal-safe atomic flag).

namespace meshnav::transport {

class StopSignal {
 public:
  /// Installs handlers for SIGINT and SIGTERM that set the flag (idempotent). A second signal
  /// while a stop is already pending restores the default action, so a stuck process can still be
  /// interrupted.
  static void install();
  static bool requested();
  static void request();
  /// Clears the flag (tests).
  static void reset();
};

}  // namespace meshnav::transport
