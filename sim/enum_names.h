#pragma once
/// @file enum_names.h
/// @brief Name tables of the simulator's option enums: value → name, name → value, "a|b|c".

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace meshnav::sim {

template <typename E, std::size_t N>
using EnumNameTable = std::array<std::pair<E, const char*>, N>;

/// The name of `value` ("?" when the table lacks it).
template <typename E, std::size_t N>
std::string enumName(const EnumNameTable<E, N>& table, E value) {
  for (const auto& [v, name] : table)
    if (v == value) return name;
  return "?";
}

/// The value named `name`; nullopt for an unknown name.
template <typename E, std::size_t N>
std::optional<E> parseEnumName(const EnumNameTable<E, N>& table, std::string_view name) {
  for (const auto& [v, n] : table)
    if (name == n) return v;
  return std::nullopt;
}

/// Every name, joined with '|' (for usage texts and error messages).
template <typename E, std::size_t N>
std::string enumNameList(const EnumNameTable<E, N>& table) {
  std::string s;
  for (const auto& [v, name] : table) s += (s.empty() ? "" : "|") + std::string(name);
  return s;
}

}  // namespace meshnav::sim
