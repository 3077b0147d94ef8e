// The programs' shared command line. See command_line.h.
#include "evidential_slam/io/command_line.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "evidential_slam/io/parameter_file.h"

namespace evidential_slam {
namespace io {
namespace {

// CLI11's formatter without its own usage line: the description holds ours.
class Formatter : public CLI::Formatter {
 public:
  std::string make_usage(const CLI::App*, std::string) const override { return ""; }
};

std::string withOption(const std::string& pattern, const std::string& option) {
  const size_t at = pattern.find("%s");
  return at == std::string::npos ? pattern
                                 : pattern.substr(0, at) + option + pattern.substr(at + 2);
}

// A number for a reader: whole numbers without an exponent (20, not 2e+01), the rest as the
// parameter parser reads them back.
std::string numberText(double v) {
  if (std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e15) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.0f", v);
    return text;
  }
  return valueText(v);
}

}  // namespace

CommandLine::CommandLine(const std::string& description, const std::string& footer) {
  app_.description(description);
  if (!footer.empty()) app_.footer(footer);
  app_.formatter(std::make_shared<Formatter>());
  app_.get_formatter()->column_width(24);
  app_.set_help_flag("-h,--help", "this text");
  // Unknown arguments are collected and reported by parse() in our words.
  app_.allow_extras();
}

CLI::Option* CommandLine::flag(const std::string& names, const std::string& help,
                               std::function<void()> on_set) {
  CLI::Option* o = app_.add_flag(names, help);
  // A bare flag reads "true"; `--flag=x` hands over x.
  o->each([o, on_set](const std::string& value) {
     if (value != "true") throw UsageError(o->get_name() + " takes no value");
     on_set();
   })
      ->trigger_on_parse()
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  return o;
}

CLI::Option* CommandLine::option(const std::string& names, const std::string& value_name,
                                 const std::string& help,
                                 std::function<void(const std::string&)> on_value) {
  return app_.add_option(names, help)
      ->option_text(value_name)
      ->expected(1)
      ->allow_extra_args(false)
      ->each(std::move(on_value))
      ->trigger_on_parse();
}

CLI::Option* CommandLine::param(ParameterAssignments* out, const std::string& help) {
  return option("--param", "NAME=VALUE", help, [out](const std::string& value) {
    const size_t eq = value.find('=');
    if (eq == std::string::npos || eq == 0) throw UsageError("--param wants NAME=VALUE");
    out->emplace_back(value.substr(0, eq), value.substr(eq + 1));
  });
}

CLI::Option* CommandLine::positional(const std::string& name, const std::string& help,
                                     std::string* value, bool required) {
  CLI::Option* o = app_.add_option(name, *value, help);
  if (required) o->required();
  return o;
}

void CommandLine::setMessages(std::string unknown_option, std::string needs_value) {
  unknown_option_ = std::move(unknown_option);
  needs_value_ = std::move(needs_value);
}

bool CommandLine::parse(const std::vector<std::string>& args, bool* help, std::string* error) {
  *help = false;
  auto bad = [&](const std::string& why) {
    if (error != nullptr) *error = why;
    return false;
  };
  // The first argument nobody declared, in our words; "" when there is none.
  auto unknown = [&]() -> std::string {
    const std::vector<std::string> extra = app_.remaining();
    if (extra.empty()) return "";
    const std::string& first = extra.front();
    if (first.empty() || first[0] != '-') return "unexpected argument '" + first + "'";
    return withOption(unknown_option_, first);
  };
  // CLI11 takes the arguments last first. `--name=` gives an option an empty value, as before
  // (CLI11 would take the next argument instead).
  std::vector<std::string> reversed;
  for (auto arg = args.rbegin(); arg != args.rend(); ++arg) {
    const CLI::Option* o = nullptr;
    if (arg->size() > 3 && arg->compare(0, 2, "--") == 0 && arg->find('=') == arg->size() - 1) {
      o = app_.get_option_no_throw(arg->substr(0, arg->size() - 1));
    }
    if (o != nullptr && o->get_items_expected_max() == 0) {
      return bad(o->get_name() + " takes no value");
    }
    if (o != nullptr) {
      reversed.emplace_back();
      reversed.push_back(arg->substr(0, arg->size() - 1));
    } else {
      reversed.push_back(*arg);
    }
  }
  try {
    app_.parse(reversed);
  } catch (const CLI::CallForHelp&) {
    *help = true;
    return true;
  } catch (const UsageError& e) {
    return bad(e.what());
  } catch (const CLI::ArgumentMismatch& e) {
    // "--name: 1 required TEXT missing" and the like: the option is before the colon.
    const std::string what = e.what();
    return bad(withOption(needs_value_, what.substr(0, what.find(':'))));
  } catch (const CLI::RequiredError& e) {
    // An unknown argument first: it may be the required option misspelt.
    const std::string why = unknown();
    return bad(why.empty() ? e.what() : why);
  } catch (const CLI::Error& e) {
    return bad(e.what());
  }
  const std::string why = unknown();
  return why.empty() || bad(why);
}

std::string CommandLine::help() const { return app_.help() + extra_help_; }

int CommandLine::parseMain(int argc, char** argv, int usage_exit) {
  bool asked = false;
  std::string error;
  if (!parse(std::vector<std::string>(argv + (argc > 0 ? 1 : 0), argv + argc), &asked, &error)) {
    std::fprintf(stderr, "error: %s (see --help)\n", error.c_str());
    return usage_exit;
  }
  if (asked) {
    std::fputs(help().c_str(), stdout);
    return 0;
  }
  return -1;
}

std::string parameterHelp(const std::string& title, const std::vector<ParameterSpec>& specs,
                          const std::vector<std::pair<std::string, std::string>>& defaults) {
  std::ostringstream out;
  out << "\n" << title << "\n";
  for (size_t i = 0; i < specs.size(); ++i) {
    const ParameterSpec& s = specs[i];
    const std::string type = std::string(s.type) == "std::string" ? "string" : s.type;
    const std::string unit = *s.unit != '\0' ? std::string(" ") + s.unit : "";
    std::string value = i < defaults.size() ? defaults[i].second : "";
    double number = 0.0;
    if (type == "double" && parseNumber(value, &number)) value = numberText(number);
    out << "  " << s.name << " = " << (value.empty() ? "\"\"" : value) << unit << "  (" << type;
    if (type == "int" || type == "double") {
      out << ", " << numberText(s.min) << " to " << numberText(s.max);
    }
    out << ")  " << s.meaning << "\n";
  }
  return out.str();
}

std::string sharedParameterHelp(const std::string& title) {
  return parameterHelp(title, sharedParameterSpecs(), parameterValues(Parameters()));
}

bool applyParameters(const std::vector<std::string>& config_files,
                     const ParameterAssignments& assignments, Parameters* params,
                     std::vector<std::string>* ignored, std::string* error) {
  for (const std::string& file : config_files) {
    std::vector<std::pair<std::string, std::string>> entries;
    if (!readParameterFile(file, &entries, error) ||
        !applyParameterEntries(entries, file, params, ignored, error)) {
      return false;
    }
  }
  for (const auto& [name, text] : assignments) {
    if (!setParameter(name, text, params, error)) return false;
  }
  return true;
}

}  // namespace io
}  // namespace evidential_slam
