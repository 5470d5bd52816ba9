#pragma once
/// @file cli_main.h
/// @brief The start-up every offline tool shares (meshnav_sim, meshnav_run, meshnav_eval,
/// meshnav_calibrate, meshnav_range_stats, dataset_to_lcmlog), so that its main is its work only:
/// logging, the command line (common/cli.h) with --help (exit 0) and a bad command line (exit 2),
/// and an exception out of the work logged as an error, exit 1. The LCM processes have the same in
/// transport::ProcessMain.
///
/// Use:
///   int main(int argc, char** argv) {
///     return cliMain<EvalCli>(argc, argv, "meshnav_eval", kDescription, declareOptions,
///                             [](const Cli&, EvalCli& c) { return run(c); });
///   }

#include <functional>
#include <string>

#include "common/cli.h"

namespace meshnav {

/// setupLogging(program), a Cli that `declare` fills, parse, then `work`, whose return value is
/// the exit code.
int cliMain(int argc, char** argv, const std::string& program, const std::string& description,
            const std::function<void(Cli&)>& declare, const std::function<int(Cli&)>& work);

/// The same with the options held here: `declare(cli, options)`, then `work(cli, options)`.
template <class Options>
int cliMain(int argc, char** argv, const std::string& program, const std::string& description,
            void (*declare)(Cli&, Options&), const std::function<int(const Cli&, Options&)>& work) {
  Options options;
  return cliMain(
      argc, argv, program, description, [&](Cli& cli) { declare(cli, options); },
      [&](Cli& cli) { return work(cli, options); });
}

}  // namespace meshnav
