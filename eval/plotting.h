#pragma once
/// @file plotting.h
/// @brief Runs the matplotlib scripts of eval/plots/ (headless, Agg backend) from the binaries.

#include <optional>
#include <string>
#include <vector>

namespace meshnav::eval {

/// Directory of the plot scripts: $MESHNAV_PLOTS_DIR if set, else the source tree's eval/plots
/// (compile definition MESHNAV_EVAL_PLOTS_DIR).
std::string plotsDir();

/// A Python interpreter that can import matplotlib: $MESHNAV_PYTHON, `python3` on PATH, then
/// /usr/bin/python3 (Debian's, which has python3-matplotlib when a pyenv python3 shadows it).
/// nullopt when none can (the caller warns and skips the plots).
std::optional<std::string> findPythonWithMatplotlib();

/// Runs `python plotsDir()/script args...`; returns true on exit code 0. Logs a warning naming the
/// missing interpreter/script otherwise. MPLBACKEND=Agg is set for the child.
bool runPlotScript(const std::string& script, const std::vector<std::string>& args);

}  // namespace meshnav::eval
