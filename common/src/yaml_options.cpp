#include "common/yaml_options.h"

#include <fstream>
#include <map>
#include <sstream>

namespace meshnav {

std::string yamlText(const YAML::Node& n) { return n && n.IsScalar() ? n.Scalar() : "?"; }

YamlOptions::YamlOptions(const YAML::Node& root, std::string file, std::string prefix)
    : file_(std::move(file)), prefix_(std::move(prefix)) {
  root_.reset(root);
}

YAML::Node YamlOptions::loadFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open file");
  std::stringstream ss;
  ss << in.rdbuf();
  YAML::Node root;
  try {
    root = YAML::Load(ss.str());
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error (" + e.msg + ")");
  }
  rejectDuplicateKeys(root, path);
  return root;
}

namespace {

void rejectDuplicateKeysIn(const YAML::Node& n, const std::string& path, const std::string& prefix) {
  if (n.IsSequence()) {
    int i = 0;
    for (const auto& e : n) rejectDuplicateKeysIn(e, path, prefix + "[" + std::to_string(i++) + "]");
    return;
  }
  if (!n.IsMap()) return;
  std::map<std::string, int> first_line;  // key → its 1-based line
  for (const auto& kv : n) {
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "?";
    const std::string full = prefix.empty() ? key : prefix + "." + key;
    const int line = kv.first.Mark().line + 1;
    if (const auto [it, fresh] = first_line.emplace(key, line); !fresh)
      throw std::runtime_error(path + ":" + std::to_string(line) + ": key '" + full + "' given twice (first at line " +
                               std::to_string(it->second) + ")");
    rejectDuplicateKeysIn(kv.second, path, full);
  }
}

}  // namespace

void YamlOptions::rejectDuplicateKeys(const YAML::Node& root, const std::string& path) {
  rejectDuplicateKeysIn(root, path, "");
}

std::string YamlOptions::fullKey(const std::string& key) const {
  return prefix_.empty() ? key : key.empty() ? prefix_ : prefix_ + "." + key;
}

void YamlOptions::fail(const std::string& key, const std::string& what) const {
  throw std::runtime_error(file_ + ": key '" + fullKey(key) + "' " + what);
}

YAML::Node YamlOptions::find(const std::string& key) const {
  YAML::Node node;
  node.reset(root_);  // (Node::operator= would overwrite the content)
  std::stringstream ss(key);
  std::string part;
  while (std::getline(ss, part, '.')) {
    if (!node || !node.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
    const YAML::Node& cnode = node;  // const lookups: the non-const operator[] inserts keys
    const YAML::Node child = cnode[part];
    if (!child) return YAML::Node(YAML::NodeType::Undefined);
    node.reset(child);
  }
  return node;
}

bool YamlOptions::has(const std::string& key) const {
  const YAML::Node n = find(key);
  return n && !n.IsNull();
}

YAML::Node YamlOptions::take(const std::string& key) {
  known_.insert(key);
  return find(key);
}

void YamlOptions::checkKnown(const YAML::Node& n, const std::string& path) const {
  for (const auto& kv : n) {
    const std::string k = kv.first.IsScalar() ? kv.first.Scalar() : "?";
    const std::string p = path.empty() ? k : path + "." + k;
    if (known_.count(p)) continue;
    const auto below = known_.lower_bound(p + ".");
    const bool parent = below != known_.end() && below->compare(0, p.size() + 1, p + ".") == 0;
    if (!parent) {
      const auto mark = kv.first.Mark();
      const std::string line = mark.line >= 0 ? ":" + std::to_string(mark.line + 1) : "";
      throw std::runtime_error(file_ + line + ": unknown key '" + fullKey(p) + "'");
    }
    if (!kv.second.IsMap()) fail(p, "must be a map");
    checkKnown(kv.second, p);
  }
}

void YamlOptions::rejectUnknown() const {
  if (!root_ || root_.IsNull()) return;
  if (!root_.IsMap()) throw std::runtime_error(file_ + ": " + (prefix_.empty() ? "the file" : "'" + prefix_ + "'") +
                                               " must be a map of keys");
  checkKnown(root_, "");
}

}  // namespace meshnav
