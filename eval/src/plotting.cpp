#include "eval/plotting.h"

#include <spdlog/spdlog.h>

#include <cstdlib>
#include <filesystem>

namespace meshnav::eval {

namespace {

/// Single-quotes `s` for /bin/sh.
std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') out += "'\\''";
    else out += c;
  }
  return out + "'";
}

bool canImportMatplotlib(const std::string& python) {
  const std::string cmd = shellQuote(python) + " -c 'import matplotlib, numpy' >/dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}

}  // namespace

std::string plotsDir() {
  if (const char* env = std::getenv("MESHNAV_PLOTS_DIR"); env && *env) return env;
#ifdef MESHNAV_EVAL_PLOTS_DIR
  return MESHNAV_EVAL_PLOTS_DIR;
#else
  return "eval/plots";
#endif
}

std::optional<std::string> findPythonWithMatplotlib() {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("MESHNAV_PYTHON"); env && *env) candidates.emplace_back(env);
  candidates.emplace_back("python3");
  candidates.emplace_back("/usr/bin/python3");
  for (const auto& c : candidates)
    if (canImportMatplotlib(c)) return c;
  return std::nullopt;
}

bool runPlotScript(const std::string& script, const std::vector<std::string>& args) {
  const std::filesystem::path path = std::filesystem::path(plotsDir()) / script;
  if (!std::filesystem::exists(path)) {
    spdlog::warn("plot script {} not found (set MESHNAV_PLOTS_DIR); no plots written", path.string());
    return false;
  }
  static const std::optional<std::string> python = findPythonWithMatplotlib();
  if (!python) {
    spdlog::warn("no Python with matplotlib and numpy found (tried $MESHNAV_PYTHON, python3, /usr/bin/python3; "
                 "install python3-matplotlib); no plots written");
    return false;
  }
  std::string cmd = "MPLBACKEND=Agg " + shellQuote(*python) + " " + shellQuote(path.string());
  for (const auto& a : args) cmd += " " + shellQuote(a);
  spdlog::debug("running {}", cmd);
  const int rc = std::system(cmd.c_str());
  if (rc != 0) {
    spdlog::warn("plot script {} failed (exit status {}); metrics are unaffected", script, rc);
    return false;
  }
  return true;
}

}  // namespace meshnav::eval
