#include "transport/process_options.h"

#include <spdlog/spdlog.h>

#include "transport/stop_signal.h"

namespace meshnav::transport {

void declareProcessOptions(Cli& cli) {
  cli.option("lcm-url").option("config").option("log-level");
}

void startProcess(const std::string& program, const Cli& cli) {
  setupLogging(program);
  if (cli.has("log-level")) spdlog::set_level(spdlog::level::from_str(cli.get("log-level")));
  StopSignal::install();
}

}  // namespace meshnav::transport
