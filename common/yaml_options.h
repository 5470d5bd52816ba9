#pragma once
/// @file yaml_options.h
/// @brief The one rule every options and setup file follows (config/estimator.yaml,
/// config/calibrator.yaml, setup.yaml; mission files follow it in mission/src/mission.cpp):
///  - a key the program does not know is an error naming the file and the key (a typo such as
///    `abs_anchor_positons` must not silently leave a default),
///  - a value of the wrong type or a number that is not finite (`.inf`, `.nan`) is an error
///    naming the file and the key, with the value found,
///  - a key given twice in one map is an error naming the file, the key and both lines (YAML
///    readers differ on which one wins; the loaders here read the first),
///  - a missing key keeps its default; defaults and units live in one place per file: the options
///    struct (and the shipped file written from it), documented in docs/configuration.md.
/// Range checks stay with each options struct (`validate()`), and their messages name the key too.
///
/// Usage: read every known key with `read` (or `take` a subtree the caller parses itself), then
/// `rejectUnknown()`.

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace meshnav {

class YamlOptions {
 public:
  /// `root`: the map of options (null: every default). `file` names the file in messages; `prefix`
  /// is the key path of `root` inside it ("calibrator" → messages say 'calibrator.sigma_range').
  YamlOptions(const YAML::Node& root, std::string file, std::string prefix = "");
  /// Loads `path` (an empty file is an empty map). Throws std::runtime_error "<path>: cannot read",
  /// on a syntax error and on a key given twice (rejectDuplicateKeys).
  static YAML::Node loadFile(const std::string& path);
  /// Throws std::runtime_error "<path>:<line>: key '<a.b>' given twice (first at line <l>)" for the
  /// first map of `root` (at any depth) that holds a key twice.
  static void rejectDuplicateKeys(const YAML::Node& root, const std::string& path);

  /// Reads `key` (dotted, relative to the root) into `field` when present; keeps the default when
  /// missing (or null). Types: bool, int, int64_t, uint64_t, double (finite), std::string,
  /// Eigen::Vector3d ([x, y, z], finite), std::optional<double>.
  template <class T>
  void read(const std::string& key, T& field);
  /// Like read, but the key must be present.
  template <class T>
  void require(const std::string& key, T& field);
  /// The subtree at `key` (null when missing), marked as known: the caller parses it.
  YAML::Node take(const std::string& key);
  /// Whether `key` is present (and not null).
  bool has(const std::string& key) const;
  /// Throws std::runtime_error "<file>: unknown key '<prefix.key>'" for the first key of the file
  /// that was neither read nor taken; also when the root is not a map.
  void rejectUnknown() const;
  /// Throws std::runtime_error "<file>: key '<prefix.key>' <what>".
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;
  /// "prefix.key" (or "key" without prefix).
  std::string fullKey(const std::string& key) const;
  const std::string& file() const { return file_; }

 private:
  YAML::Node find(const std::string& key) const;
  template <class T>
  T convert(const YAML::Node& n, const std::string& key) const;
  void checkKnown(const YAML::Node& n, const std::string& path) const;

  YAML::Node root_;
  std::string file_, prefix_;
  std::set<std::string> known_;
};

/// Scalar text of a node for messages ("?" when not a scalar).
std::string yamlText(const YAML::Node& n);

template <class T>
T YamlOptions::convert(const YAML::Node& n, const std::string& key) const {
  if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
    if (!n.IsSequence() || n.size() != 3) fail(key, "must be a list of 3 numbers [x, y, z]");
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = convert<double>(n[i], key + "[" + std::to_string(i) + "]");
    return v;
  } else {
    if (!n.IsScalar()) fail(key, "must be a single value, not a list or map");
    T v{};
    try {
      v = n.as<T>();
    } catch (const YAML::Exception&) {
      const char* what = std::is_same_v<T, bool>            ? "true or false"
                         : std::is_floating_point_v<T>      ? "a number"
                         : std::is_unsigned_v<T>            ? "a non-negative integer"
                         : std::is_integral_v<T>            ? "an integer"
                                                            : "a string";
      fail(key, std::string("must be ") + what + ", got '" + n.Scalar() + "'");
    }
    if constexpr (std::is_floating_point_v<T>) {
      if (!std::isfinite(v)) fail(key, "must be a finite number, got '" + n.Scalar() + "'");
    }
    return v;
  }
}

template <class T>
void YamlOptions::read(const std::string& key, T& field) {
  known_.insert(key);
  const YAML::Node n = find(key);
  if (!n || n.IsNull()) return;
  if constexpr (std::is_same_v<T, std::optional<double>>) {
    field = convert<double>(n, key);
  } else {
    field = convert<T>(n, key);
  }
}

template <class T>
void YamlOptions::require(const std::string& key, T& field) {
  if (!has(key)) fail(key, "is missing");
  read(key, field);
}

}  // namespace meshnav
