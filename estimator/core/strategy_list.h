#pragma once
/// @file strategy_list.h
/// @brief The fusion strategies this build implements: their names (the `strategy` option and
/// every `--strategy`) and one line each for the help texts. `makeStrategy`
/// (estimator/filter/strategy_factory.cpp) builds each of them; `StrategyFactory.EveryListedStrategyIsBuilt`
/// checks that the two agree. A new strategy adds its entry here (docs/contributing.md, "A new
/// fusion strategy").

#include <array>
#include <string>
#include <string_view>

namespace meshnav::estimator {

struct StrategyListEntry {
  std::string_view name;     ///< as in the options and on the command line
  std::string_view summary;  ///< a few words for --help
};

inline constexpr std::array kStrategyList{
    StrategyListEntry{"centralized", "dense EKF"},
    StrategyListEntry{"dp", "modular, centralized-equivalent"},
    StrategyListEntry{"dah", "modular, updates only the involved instances"},
};

/// True for a name in kStrategyList.
inline bool strategyListed(const std::string& name) {
  for (const auto& s : kStrategyList)
    if (s.name == name) return true;
  return false;
}

/// The names joined by `separator` ("centralized|dp|dah").
inline std::string strategyNames(std::string_view separator = "|") {
  std::string out;
  for (const auto& s : kStrategyList) out += (out.empty() ? "" : std::string(separator)) + std::string(s.name);
  return out;
}

/// "centralized (dense EKF), dp (…), dah (…)" for help texts.
inline std::string strategySummaries() {
  std::string out;
  for (const auto& s : kStrategyList)
    out += (out.empty() ? "" : ", ") + std::string(s.name) + " (" + std::string(s.summary) + ")";
  return out;
}

}  // namespace meshnav::estimator
