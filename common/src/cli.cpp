#include "common/cli.h"
#include "common/log_context.h"

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <map>
#include <optional>

namespace meshnav {
namespace {

/// CLI11 reads the `--config` file through this: a flat YAML map, option name → one value.
class YamlOptionsFile : public CLI::Config {
 public:
  std::string to_config(const CLI::App*, bool, bool, std::string) const override { return {}; }

  std::vector<CLI::ConfigItem> from_config(std::istream& input) const override {
    YAML::Node root;
    try {
      root = YAML::Load(input);
    } catch (const YAML::Exception& e) {
      throw CLI::ConfigError(std::string("not valid YAML: ") + e.what());
    }
    std::vector<CLI::ConfigItem> items;
    if (root.IsNull()) return items;
    if (!root.IsMap()) throw CLI::ConfigError("expected a map of option: value");
    for (const auto& kv : root) {
      const std::string key = kv.first.as<std::string>();
      if (!kv.second.IsScalar()) throw CLI::ConfigError("option '" + key + "' must be a single value");
      CLI::ConfigItem item;
      item.name = key;
      std::replace(item.name.begin(), item.name.end(), '_', '-');
      spelled_[item.name] = key;
      item.inputs = {kv.second.as<std::string>()};
      items.push_back(std::move(item));
    }
    return items;
  }

  /// The key as written in the file for an option name read from it.
  std::string spelled(const std::string& name) const {
    const auto it = spelled_.find(name);
    return it == spelled_.end() ? name : it->second;
  }

 private:
  mutable std::map<std::string, std::string> spelled_;
};

/// A number parsed whole from `text`, or nullopt.
std::optional<double> number(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size()) return std::nullopt;
  return v;
}

CLI::Validator numberCheck(const std::string& description, bool (*ok)(double)) {
  return CLI::Validator(
      [description, ok](std::string& text) -> std::string {
        const auto v = number(text);
        if (!v) return "'" + text + "' is not a number";
        if (!ok(*v)) return "must be a finite number " + description + ", got '" + text + "'";
        return {};
      },
      description);
}

/// `text` with line breaks between words so that no line is longer than `width` (longer words stay).
std::string wrap(const std::string& text, size_t width) {
  std::string out, line, word;
  auto flushWord = [&] {
    if (word.empty()) return;
    if (!line.empty() && line.size() + 1 + word.size() > width) {
      out += line + "\n";
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
    word.clear();
  };
  for (const char c : text) {
    if (c == ' ' || c == '\n') {
      flushWord();
      if (c == '\n') {
        out += line + "\n";
        line.clear();
      }
    } else {
      word += c;
    }
  }
  flushWord();
  return out + line;
}

/// Total width of --help lines [characters].
constexpr size_t kHelpWidth = 100;
constexpr size_t kHelpColumn = 30;

/// --help lines as "  --name META   what it does; constraint (default X)": the default and the
/// checks come from the declaration (CLI11's own layout puts them into the metavariable).
class HelpFormatter : public CLI::Formatter {
 public:
  std::string make_option_opts(const CLI::Option* opt) const override {
    if (opt->get_type_size() == 0) return {};
    const std::string full = opt->get_type_name();
    std::string out = " " + full.substr(0, full.find(':'));
    if (opt->get_expected_max() == CLI::detail::expected_max_vector_size) out += " ...";
    if (opt->get_required()) out += " (required)";
    return out;
  }
  std::string make_option_desc(const CLI::Option* opt) const override {
    std::string d = opt->get_description();
    const std::string full = opt->get_type_name();
    if (const auto colon = full.find(':'); colon != std::string::npos && opt->get_type_size() != 0) {
      std::string checks = full.substr(colon + 1);
      std::replace(checks.begin(), checks.end(), ':', ',');
      d += "; " + checks;
    }
    if (!opt->get_default_str().empty()) d += " (default " + opt->get_default_str() + ")";
    return wrap(d, kHelpWidth - kHelpColumn);
  }
  std::string make_description(const CLI::App* app) const override {
    return wrap(app->get_description(), kHelpWidth) + "\n\n";
  }
  std::string make_footer(const CLI::App* app) const override {
    return app->get_footer().empty() ? std::string() : wrap(app->get_footer(), kHelpWidth) + "\n";
  }
};

}  // namespace

Cli::Cli(std::string program, const std::string& description) : program_(std::move(program)), app_(description, program_) {
  app_.set_help_flag("-h,--help", "print this text and exit");
  auto formatter = std::make_shared<HelpFormatter>();
  formatter->column_width(kHelpColumn);
  app_.formatter(formatter);
}

CLI::Option* Cli::flag(const std::string& name, bool& value, const std::string& help) {
  return app_.add_flag("--" + name, value, help);
}

CLI::Option* Cli::idList(const std::string& name, std::vector<int32_t>& ids, const std::string& help) {
  return app_.add_option("--" + name, ids, help)
      ->delimiter(',')
      ->type_name("ID,ID,...")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            char* end = nullptr;
            errno = 0;
            const long long v = std::strtoll(text.c_str(), &end, 10);
            if (text.empty() || end != text.c_str() + text.size()) return "'" + text + "' is not an id";
            if (errno == ERANGE || v < 0 || v > std::numeric_limits<int32_t>::max())
              return "id " + text + " is out of range [0, " + std::to_string(std::numeric_limits<int32_t>::max()) + "]";
            return {};
          },
          "ids in [0, 2147483647]"));
}

CLI::Option* Cli::optionsFile(const std::string& help) {
  auto file = std::make_shared<YamlOptionsFile>();
  app_.config_formatter(file);
  spelled_ = [file](const std::string& name) { return file->spelled(name); };
  options_file_ = app_.set_config("--config", "", help);
  options_file_->configurable(false);
  options_file_->type_name("FILE");
  app_.allow_config_extras(false);
  return options_file_;
}

bool Cli::given(const std::string& name) const { return app_.count("--" + name) > 0; }

bool Cli::parse(int argc, char** argv, int& exit_code) {
  return handle([&] { app_.parse(argc, argv); }, exit_code);
}

bool Cli::parse(const std::vector<std::string>& args, int& exit_code) {
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 takes them last first
  return handle([&] { app_.parse(reversed); }, exit_code);
}

bool Cli::handle(const std::function<void()>& parse_call, int& exit_code) {
  error_.clear();
  try {
    parse_call();
    exit_code = 0;
    return true;
  } catch (const CLI::CallForHelp&) {
    std::cout << app_.help() << std::flush;
    exit_code = 0;
    return false;
  } catch (const CLI::ParseError& e) {
    error_ = e.what();
    const bool from_file = dynamic_cast<const CLI::ConfigError*>(&e) != nullptr ||
                           (dynamic_cast<const CLI::FileError*>(&e) != nullptr && options_file_);
    if (from_file && options_file_ && options_file_->count() > 0) {
      const std::string path = options_file_->as<std::string>();
      const std::string extras = "INI was not able to parse ";
      if (error_.rfind(extras, 0) == 0) error_ = "unknown option '" + spelled_(error_.substr(extras.size())) + "'";
      if (error_.find(path) == std::string::npos) error_ = path + ": " + error_;
    }
    std::cerr << program_ << ": " << error_ << "\nRun with --help for the options." << std::endl;
    exit_code = 2;
    return false;
  }
}

namespace cli {
CLI::Validator finite() {
  return numberCheck("finite", [](double v) { return std::isfinite(v); });
}
CLI::Validator nonNegative() {
  return numberCheck(">= 0", [](double v) { return std::isfinite(v) && v >= 0.0; });
}
CLI::Validator positive() {
  return numberCheck("> 0", [](double v) { return std::isfinite(v) && v > 0.0; });
}
CLI::Validator oneOf(std::function<bool(const std::string&)> accepts, const std::string& names) {
  return CLI::Validator(
      [accepts, names](std::string& text) -> std::string {
        return accepts(text) ? std::string() : "'" + text + "' is not one of " + names;
      },
      names);
}
}  // namespace cli

void setupLogging(const std::string& program) {
  setLogPattern(program);  // with the vehicle of a fleet in one process (common/log_context.h)
  const char* lvl = std::getenv("MESHNAV_LOG_LEVEL");
  if (lvl) spdlog::set_level(spdlog::level::from_str(lvl));
}

CLI::Option* Cli::fleetServing(std::string& fleet_path, std::string& bus, const std::string& fleet_help) {
  CLI::Option* fleet = optional("fleet", fleet_path, fleet_help)->type_name("FILE");
  option("bus", bus,
         "with --fleet: per-vehicle (vehicle k on --lcm-url's port + 1 + k, as meshnav_fleet_launch --bus) or "
         "shared (every vehicle on --lcm-url)")
      ->type_name("BUS")
      ->check(CLI::IsMember({"per-vehicle", "shared"}));
  if (CLI::Option* prefix = app_.get_option_no_throw("--channel-prefix")) fleet->excludes(prefix);
  return fleet;
}

}  // namespace meshnav
