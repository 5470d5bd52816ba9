#pragma once
/// @file options_list.h
/// @brief How an options struct lists its options (estimator/core/estimator_options.cpp,
/// calibrator/src/calibrator_options.cpp, calibrator/node/calibrator_node_options.cpp): one table
/// of OptionField {key, where the member is, comment}, the only place a field is named; from it
/// the options are read from a file the one way of common/yaml_options.h, checked with the file's
/// name in the message, and printed ("  key: value" lines, or the shipped file).
///
/// Use (in the options' .cpp):
///   using Ref = std::variant<double*, int*, bool*>;          // the types of its members
///   template <auto... path> constexpr auto at = &memberAt<MyOptions, Ref, path...>;
///   const OptionField<MyOptions, Ref> kFields[] = {
///       {"rate_hz", at<&MyOptions::rate_hz>, "[Hz]"},
///       {"time.max_offset_s", at<&MyOptions::time, &TimeGuardOptions::max_offset_s>},
///   };
///   auto list = [](auto& o, auto&& f) { forEachOption(o, kFields, f); };
///   MyOptions o = readOptionsList<MyOptions>(yaml, list);

#include <cstddef>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>

#include "common/yaml_options.h"

namespace meshnav {

/// One option of `Opts`: its key, where it lives (`at(o)`: a pointer to the member, one of the
/// types of the variant `Ref`) and the comment written after it in a shipped file (may be null).
template <class Opts, class Ref>
struct OptionField {
  const char* key;
  Ref (*at)(Opts&);
  const char* unit = nullptr;
};

/// `at` of an OptionField: the member of `o` reached by the member pointers `path` (one, or a
/// section and its member).
template <class Opts, class Ref, auto... path>
Ref memberAt(Opts& o) {
  return &(o .* ... .* path);
}

/// Calls `v(key, field, unit)` for every option of `table`, in its order; a const `o` gives const
/// fields (the cast only finds the member).
template <class Opts, class Field, size_t N, class Visitor>
void forEachOption(Opts& o, const Field (&table)[N], Visitor&& v) {
  for (const Field& f : table) {
    std::visit(
        [&](auto* member) {
          if constexpr (std::is_const_v<Opts>) {
            v(f.key, std::as_const(*member), f.unit);
          } else {
            v(f.key, *member, f.unit);
          }
        },
        f.at(const_cast<std::remove_const_t<Opts>&>(o)));
  }
}

/// Reads `field` at `key`; an options struct overloads this (found by argument-dependent lookup)
/// for a field of its own type, e.g. an enum read by name.
template <class T>
void readOption(YamlOptions& yaml, const std::string& key, T& field) {
  yaml.read(key, field);
}

/// Prints a value as "true"/"false" or as `<<` does; overloaded like readOption.
template <class T>
void printOption(std::ostream& os, const T& value) {
  if constexpr (std::is_same_v<T, bool>) {
    os << (value ? "true" : "false");
  } else {
    os << value;
  }
}

/// Options read from `yaml`: every field of `list` (a missing key keeps its default), unknown
/// keys refused (file and key), then `validate()`, whose message gets the file's name in front
/// ("<file>: <what>").
/// `base`: the values a missing key keeps (default: `Opts{}`; e.g. a profile's).
template <class Opts, class List>
Opts readOptionsList(YamlOptions& yaml, List&& list, Opts base = Opts{}) {
  Opts o = std::move(base);
  list(o, [&](const auto& key, auto& field, auto&&...) { readOption(yaml, key, field); });
  yaml.rejectUnknown();
  try {
    o.validate();
  } catch (const std::exception& e) {
    throw std::runtime_error(yaml.file() + ": " + e.what());
  }
  return o;
}

/// "  key: value\n" for every field of `list`.
template <class Opts, class List>
std::string printOptionsList(const Opts& o, List&& list) {
  std::ostringstream s;
  list(o, [&](const auto& key, const auto& field, auto&&...) {
    s << "  " << key << ": ";
    printOption(s, field);
    s << "\n";
  });
  return s.str();
}

}  // namespace meshnav
