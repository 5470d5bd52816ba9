/// @file log_context.cpp
/// @brief LogContext and the spdlog flag that prints it (log_context.h).

#include "common/log_context.h"

#include <spdlog/pattern_formatter.h>
#include <spdlog/spdlog.h>

#include <memory>

namespace meshnav {

namespace {

thread_local const std::string* t_context = nullptr;

/// `%*`: " <context>" inside a LogContext::Scope, nothing outside.
class ContextFlag : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg&, const std::tm&, spdlog::memory_buf_t& dest) override {
    if (const std::string* c = t_context; c && !c->empty()) {
      dest.push_back(' ');
      dest.append(c->data(), c->data() + c->size());
    }
  }
  std::unique_ptr<custom_flag_formatter> clone() const override { return std::make_unique<ContextFlag>(); }
};

}  // namespace

const std::string* LogContext::current() { return t_context; }

LogContext::Scope::Scope(const std::string* name) : previous_(t_context) { t_context = name; }

LogContext::Scope::~Scope() { t_context = previous_; }

void setLogPattern(const std::string& program) {
  auto formatter = std::make_unique<spdlog::pattern_formatter>();
  formatter->add_flag<ContextFlag>('*').set_pattern("[%H:%M:%S.%e] [" + program + "%*] [%^%l%$] %v");
  spdlog::set_formatter(std::move(formatter));
}

}  // namespace meshnav
