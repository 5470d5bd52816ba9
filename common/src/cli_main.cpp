#include "common/cli_main.h"

#include <spdlog/spdlog.h>

#include <exception>

namespace meshnav {

int cliMain(int argc, char** argv, const std::string& program, const std::string& description,
            const std::function<void(Cli&)>& declare, const std::function<int(Cli&)>& work) {
  setupLogging(program);
  Cli cli(program, description);
  declare(cli);
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  try {
    return work(cli);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}

}  // namespace meshnav
