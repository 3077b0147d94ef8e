// The programs' shared command line (io/command_line.h): callbacks in command-line order, the
// one-line errors, --help, and the --param listing generated from the parameter table.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "evidential_slam/io/command_line.h"

namespace evidential_slam {
namespace io {
namespace {

// A command line with a flag, a checked value, a plain value and --param, logging every callback.
struct Fixture {
  CommandLine cl{"usage: prog [options]\nWhat prog does.", "Exit codes: 0 fine."};
  std::vector<std::string> log;
  ParameterAssignments params;
  Fixture() {
    cl.flag("-q,--quiet", "be quiet", [this] { log.push_back("quiet"); });
    cl.option("--count", "N", "how many", [this](const std::string& v) {
      int n = 0;
      if (!parseNumber(v, &n) || n < 1) throw UsageError("--count wants an integer >= 1");
      log.push_back("count " + v);
    });
    cl.option("--name", "TEXT", "a name", [this](const std::string& v) {
      log.push_back("name " + v);
      params.emplace_back("name", v);  // a shorthand: joins --param's list where it stands
    });
    cl.param(&params, "a parameter");
  }
  bool parse(const std::vector<std::string>& args, std::string* error, bool* help = nullptr) {
    bool h = false;
    const bool ok = cl.parse(args, &h, error);
    if (help != nullptr) *help = h;
    return ok;
  }
};

TEST(CommandLine, CallbacksRunInCommandLineOrder) {
  Fixture f;
  std::string error;
  ASSERT_TRUE(f.parse({"--param", "a=1", "--name", "x", "--count=3", "-q", "--param=b=2", "--name",
                       "-y", "--count", "4"},
                      &error))
      << error;
  EXPECT_EQ(f.log, (std::vector<std::string>{"name x", "count 3", "quiet", "name -y", "count 4"}));
  EXPECT_EQ(f.params,
            (ParameterAssignments{{"a", "1"}, {"name", "x"}, {"b", "2"}, {"name", "-y"}}));
}

// `--name=` is an empty value, not a request for the next argument.
TEST(CommandLine, AnEmptyValueAfterTheEqualsSign) {
  Fixture f;
  std::string error;
  ASSERT_TRUE(f.parse({"--name=", "--count", "2"}, &error)) << error;
  EXPECT_EQ(f.log, (std::vector<std::string>{"name ", "count 2"}));
  Fixture g;
  EXPECT_FALSE(g.parse({"--count="}, &error));
  EXPECT_EQ(error, "--count wants an integer >= 1");
  Fixture h;
  EXPECT_FALSE(h.parse({"--quiet="}, &error));
  EXPECT_EQ(error, "--quiet takes no value");
}

TEST(CommandLine, BadUsageIsOneLineNamingTheOption) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--bogus"}, "unknown option '--bogus'"},
      {{"--bogus=1", "--count", "2"}, "unknown option '--bogus=1'"},
      {{"stray"}, "unexpected argument 'stray'"},
      {{"--count"}, "--count needs a value"},
      {{"--count", "0"}, "--count wants an integer >= 1"},
      {{"--count", "many"}, "--count wants an integer >= 1"},
      {{"--quiet=1"}, "--quiet takes no value"},
      {{"--quiet=false"}, "--quiet takes no value"},
      {{"--param", "a"}, "--param wants NAME=VALUE"},
      {{"--param", "=1"}, "--param wants NAME=VALUE"},
  };
  for (const auto& [args, message] : cases) {
    Fixture f;
    std::string error;
    EXPECT_FALSE(f.parse(args, &error)) << ::testing::PrintToString(args);
    EXPECT_EQ(error, message) << ::testing::PrintToString(args);
  }
  Fixture f;
  f.cl.setMessages("unknown option %s", "%s wants a value");
  std::string error;
  EXPECT_FALSE(f.parse({"--frob"}, &error));
  EXPECT_EQ(error, "unknown option --frob");
  Fixture g;
  g.cl.setMessages("unknown option %s", "%s wants a value");
  EXPECT_FALSE(g.parse({"--name"}, &error));
  EXPECT_EQ(error, "--name wants a value");
}

TEST(CommandLine, HelpWinsAndListsTheOptions) {
  Fixture f;
  std::string error;
  bool help = false;
  EXPECT_TRUE(f.parse({"--count", "2", "--help"}, &error, &help)) << error;
  EXPECT_TRUE(help);
  EXPECT_TRUE(Fixture().parse({"-h"}, &error, &help));
  EXPECT_TRUE(help);
  f.cl.appendHelp("\nAppended.\n");
  const std::string text = f.cl.help();
  for (const char* part :
       {"usage: prog [options]\nWhat prog does.", "\n  -q,--quiet ", "\n  --count N ", "how many",
        "\n  --param NAME=VALUE ", "Exit codes: 0 fine.", "\nAppended.\n"}) {
    EXPECT_NE(text.find(part), std::string::npos) << part << " in:\n" << text;
  }
}

// --help names every shared parameter once, with its default, unit and range from the table.
TEST(CommandLine, ParameterHelpListsEveryParameterOnce) {
  const std::string text = sharedParameterHelp("Parameters:");
  const std::vector<ParameterSpec> specs = sharedParameterSpecs();
  const auto defaults = parameterValues(Parameters());
  ASSERT_EQ(specs.size(), defaults.size());
  ASSERT_GE(specs.size(), 50u);
  for (size_t i = 0; i < specs.size(); ++i) {
    const std::string line = "\n  " + std::string(specs[i].name) + " = ";
    const size_t at = text.find(line);
    ASSERT_NE(at, std::string::npos) << specs[i].name;
    EXPECT_EQ(text.find(line, at + 1), std::string::npos) << specs[i].name << " twice";
    // The default as shown: the same number (whole ones without an exponent) or text.
    const size_t begin = at + line.size();
    const std::string shown = text.substr(begin, text.find_first_of(" \n", begin) - begin);
    double shown_number = 0.0, number = 0.0;
    if (parseNumber(defaults[i].second, &number)) {
      ASSERT_TRUE(parseNumber(shown, &shown_number)) << specs[i].name << ": " << shown;
      EXPECT_EQ(shown_number, number) << specs[i].name;
    } else {
      EXPECT_EQ(shown, defaults[i].second.empty() ? "\"\"" : defaults[i].second) << specs[i].name;
    }
  }
  EXPECT_NE(text.find("\n  particles = 100  (int, 1 to 10000)  Number of particles K"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("\n  resolution = 0.05 m  (double, 0.005 to 2)  Map cell size"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("\n  usable_range = 20 m  (double, 0.1 to 200)  "), std::string::npos)
      << text;
}

TEST(CommandLine, ApplyParametersFilesThenAssignments) {
  Parameters p;
  std::vector<std::string> ignored;
  std::string error;
  EXPECT_TRUE(applyParameters({}, {{"particles", "7"}, {"particles", "9"}}, &p, &ignored, &error))
      << error;
  EXPECT_EQ(p.slam.particles, 9);
  EXPECT_FALSE(applyParameters({}, {{"particles", "many"}}, &p, &ignored, &error));
  EXPECT_NE(error.find("particles"), std::string::npos) << error;
  EXPECT_FALSE(applyParameters({"/nonexistent.yaml"}, {}, &p, &ignored, &error));
  EXPECT_NE(error.find("/nonexistent.yaml"), std::string::npos) << error;
}

}  // namespace
}  // namespace io
}  // namespace evidential_slam
