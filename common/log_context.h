#pragma once
/// @file log_context.h
/// @brief Which vehicle a log line is about, for a fleet in one process (`meshnav_run --fleet`):
/// every estimator logs through spdlog's default logger, so without it "estimator: health lost"
/// does not say whose. The pipeline opens a Scope with the vehicle's name around each call into
/// that vehicle's estimator; setupLogging's pattern prints it after the program name
/// ("[meshnav_run v2] [warning] estimator: ..."). Per thread; nothing is printed outside a scope.

#include <string>

namespace meshnav {

class LogContext {
 public:
  /// This thread's context, or nullptr outside any scope.
  static const std::string* current();

  /// Sets the context for its lifetime (nested scopes restore the outer one). `name` must outlive
  /// the scope; a null `name` is no context.
  class Scope {
   public:
    explicit Scope(const std::string* name);
    ~Scope();
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    const std::string* previous_;
  };
};

/// Installs the default logger's pattern for `program` with the context flag (setupLogging's).
void setLogPattern(const std::string& program);

}  // namespace meshnav
