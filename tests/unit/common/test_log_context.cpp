// LogContext (common/log_context.h): the vehicle of a fleet in one process in every log line.
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <memory>
#include <sstream>

#include "common/log_context.h"

// A fleet in one process: a log line inside a LogContext scope names its vehicle after the program.
TEST(LogContext, ALineInsideAScopeNamesItsVehicle) {
  auto stream = std::make_shared<std::ostringstream>();
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(*stream);
  const auto previous = spdlog::default_logger();
  spdlog::set_default_logger(std::make_shared<spdlog::logger>("test", sink));
  meshnav::setLogPattern("meshnav_run");
  const std::string v2 = "v2", v3 = "v3";
  spdlog::info("fleet line");
  {
    const meshnav::LogContext::Scope scope(&v2);
    spdlog::warn("estimator: health lost");
    {
      const meshnav::LogContext::Scope inner(&v3);
      EXPECT_EQ(meshnav::LogContext::current(), &v3);
      spdlog::info("inner");
    }
    EXPECT_EQ(meshnav::LogContext::current(), &v2);
  }
  EXPECT_EQ(meshnav::LogContext::current(), nullptr);
  spdlog::info("after");
  spdlog::set_default_logger(previous);
  const std::string out = stream->str();
  EXPECT_NE(out.find("[meshnav_run] [info] fleet line"), std::string::npos) << out;
  EXPECT_NE(out.find("[meshnav_run v2] [warning] estimator: health lost"), std::string::npos) << out;
  EXPECT_NE(out.find("[meshnav_run v3] [info] inner"), std::string::npos) << out;
  EXPECT_NE(out.find("[meshnav_run] [info] after"), std::string::npos) << out;
}
