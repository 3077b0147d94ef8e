// evidential_slam_explore: one exploration run without ROS (io::runExploration: the grid-map
// simulator driven by the explorer, mapped by the SLAM engine), written as <out>/exploration.json
// — the file explore.launch writes. scripts/benchmark-exploration runs it over worlds, strategies
// and seeds.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "evidential_slam/core/exploration/parameters.h"
#include "evidential_slam/core/parameters.h"
#include "evidential_slam/io/command_line.h"
#include "evidential_slam/io/exploration_run.h"
#include "evidential_slam/io/gridmap_simulator.h"
#include "evidential_slam/io/parameter_file.h"

namespace {

bool setAnyParameter(const std::string& name, const std::string& value,
                     evidential_slam::Parameters* slam, evidential_slam::io::ExplorationRunConfig* c,
                     std::string* why) {
  namespace es = evidential_slam;
  std::string ignored;
  if (es::exploration::setExplorerParameter(name, value, &c->explorer, &ignored)) return true;
  if (es::setParameter(name, value, slam, &ignored)) return true;
  for (const auto& field : es::io::gridmapSimulatorFields(&c->simulator)) {
    if (name != field.name) continue;
    try {
      std::visit(
          [&](auto* v) {
            using T = std::decay_t<decltype(*v)>;
            if constexpr (std::is_same_v<T, std::string>) *v = value;
            else if constexpr (std::is_same_v<T, bool>) *v = value == "true";
            else if constexpr (std::is_same_v<T, int>) *v = std::stoi(value);
            else *v = std::stod(value);
          },
          field.value);
    } catch (const std::exception&) {
      *why = "simulator parameter " + name + " wants a number, not '" + value + "'";
      return false;
    }
    return true;
  }
  *why = "unknown or bad parameter " + name + "=" + value;
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  namespace es = evidential_slam;
  using es::io::UsageError;
  es::io::ExplorationRunConfig c;
  es::Parameters slam;
  std::string out, why, config_error;
  es::io::ParameterAssignments params;
  double start[3] = {0.0, 0.0, 0.0};
  c.simulator.resolution = 0.05;
  auto number = [](const char* option, auto* to) {
    return [option, to](const std::string& v) {
      if (!es::io::parseNumber(v, to)) {
        throw UsageError("bad value '" + v + "' for " + option);
      }
    };
  };
  es::io::CommandLine cl(std::string("usage: ") + argv[0] + " --map PNG --out DIR [options]", "");
  cl.setMessages("unknown option %s", "%s wants a value");
  cl.option("--map", "PNG", "the world (dark = obstacle) or a map_server .yaml",
            [&](const std::string& v) { c.simulator.map = v; });
  cl.option("--resolution", "M", "m per pixel (default 0.05)",
            number("--resolution", &c.simulator.resolution));
  cl.option("--start", "X,Y,YAW", "start pose in the image's frame, centred (default 0,0,0)",
            [&](const std::string& v) {
              std::vector<double> p;
              if (!es::io::parseNumberList(v, 3, 3, &p)) {
                throw UsageError("bad value '" + v + "' for --start");
              }
              std::copy(p.begin(), p.end(), start);
            });
  cl.option("--strategy", "NAME", "ns, entropy or frontier (default ns)",
            [&](const std::string& v) { params.emplace_back("strategy", v); });
  cl.option("--seed", "N", "simulator and SLAM seed (default 1)", [&](const std::string& v) {
    number("--seed", &c.simulator.seed)(v);
    params.emplace_back("seed", v);
  });
  cl.option("--max-time", "S", "simulated s at most (default 600)",
            number("--max-time", &c.max_time));
  // A parameter file's entries join the --param list where the file stands.
  cl.option("--config", "FILE", "SLAM parameter file (e.g. config/sim.yaml)",
            [&](const std::string& v) {
              std::vector<std::pair<std::string, std::string>> entries;
              if (!es::io::readParameterFile(v, &entries, &why)) {
                if (config_error.empty()) config_error = why;
                return;
              }
              params.insert(params.end(), entries.begin(), entries.end());
            });
  cl.param(&params,
           "a SLAM, explorer or simulator parameter (repeatable; below,\n"
           "and evidential_slam_simulate --help for the simulator's)");
  cl.option("--out", "DIR", "where exploration.json goes (created)",
            [&](const std::string& v) { out = v; });
  es::exploration::ExplorerConfig explorer_defaults;
  cl.appendHelp(es::io::parameterHelp(
      "Explorer parameters (--param NAME=VALUE; the default and unit, the type and range):",
      es::exploration::explorerParameterSpecs(),
      es::exploration::explorerParameterValues(explorer_defaults)));
  cl.appendHelp(es::io::sharedParameterHelp("SLAM parameters (--param, --config):"));
  if (const int code = cl.parseMain(argc, argv, 2); code >= 0) return code;
  if (!config_error.empty()) {
    std::fprintf(stderr, "error: %s\n", config_error.c_str());
    return 2;
  }
  if (c.simulator.map.empty() || out.empty()) {
    std::fprintf(stderr, "error: --map and --out are required (see --help)\n");
    return 2;
  }
  c.simulator.start_x = start[0];
  c.simulator.start_y = start[1];
  c.simulator.start_theta = start[2];
  for (const auto& [name, value] : params) {
    if (!setAnyParameter(name, value, &slam, &c, &why)) {
      std::fprintf(stderr, "error: %s\n", why.c_str());
      return 2;
    }
  }
  c.slam = slam.slam;
  es::io::ExplorationRunResult r;
  if (!es::io::runExploration(c, &r, &why)) {
    std::fprintf(stderr, "error: %s\n", why.c_str());
    return 1;
  }
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (!es::io::writeExplorationJson(out + "/exploration.json", r, &why)) {
    std::fprintf(stderr, "error: %s\n", why.c_str());
    return 1;
  }
  std::printf("%s: coverage %.4f (%.4f beyond the %.3f m gap band) after %.1f m in %.1f s "
              "simulated, %llu collision(s), to 90 %%: %.0f s; %s\n",
              c.explorer.frontiers.strategy.c_str(), r.final_coverage,
              r.final_coverage_beyond_gap, r.gap_band_m, r.distance_m, r.sim_time_s,
              static_cast<unsigned long long>(r.collisions), r.time_to_90_s,
              r.stop_reason.c_str());
  return 0;
}
