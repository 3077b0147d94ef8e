// evidential_slam_explore: one exploration run without ROS (io::runExploration: the grid-map
// simulator driven by the explorer, mapped by the SLAM engine), written as <out>/exploration.json
// — the file explore.launch writes. scripts/benchmark-exploration runs it over worlds, strategies
// and seeds.
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "evidential_slam/core/exploration/parameters.h"
#include "evidential_slam/core/parameters.h"
#include "evidential_slam/io/exploration_run.h"
#include "evidential_slam/io/gridmap_simulator.h"
#include "evidential_slam/io/parameter_file.h"

namespace {

const char kUsage[] =
    "usage: %s --map PNG --out DIR [options]\n"
    "  --map PNG            the world (dark = obstacle) or a map_server .yaml\n"
    "  --resolution M       m per pixel (default 0.05)\n"
    "  --start X,Y,YAW      start pose in the image's frame, centred (default 0,0,0)\n"
    "  --strategy NAME      ns, entropy or frontier (default ns)\n"
    "  --seed N             simulator and SLAM seed (default 1)\n"
    "  --max-time S         simulated s at most (default 600)\n"
    "  --config FILE        SLAM parameter file (e.g. config/sim.yaml)\n"
    "  --param NAME=VALUE   a SLAM, explorer or simulator parameter (repeatable)\n"
    "  --out DIR            where exploration.json goes (created)\n";

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
  es::io::ExplorationRunConfig c;
  es::Parameters slam;
  std::string out, why;
  std::vector<std::pair<std::string, std::string>> params;
  double start[3] = {0.0, 0.0, 0.0};
  c.simulator.resolution = 0.05;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::printf(kUsage, argv[0]);
      return 0;
    }
    if (i + 1 >= argc) {
      std::fprintf(stderr, "error: %s wants a value (see --help)\n", a.c_str());
      return 2;
    }
    const std::string v = argv[++i];
    try {
      if (a == "--map") {
        c.simulator.map = v;
      } else if (a == "--resolution") {
        c.simulator.resolution = std::stod(v);
      } else if (a == "--start") {
        if (std::sscanf(v.c_str(), "%lf,%lf,%lf", &start[0], &start[1], &start[2]) != 3) {
          throw std::invalid_argument(v);
        }
      } else if (a == "--strategy") {
        params.emplace_back("strategy", v);
      } else if (a == "--seed") {
        params.emplace_back("seed", v);
        c.simulator.seed = std::stoi(v);
      } else if (a == "--max-time") {
        c.max_time = std::stod(v);
      } else if (a == "--config") {
        std::vector<std::pair<std::string, std::string>> entries;
        if (!es::io::readParameterFile(v, &entries, &why)) {
          std::fprintf(stderr, "error: %s\n", why.c_str());
          return 2;
        }
        params.insert(params.end(), entries.begin(), entries.end());
      } else if (a == "--param") {
        const size_t eq = v.find('=');
        if (eq == std::string::npos) throw std::invalid_argument(v);
        params.emplace_back(v.substr(0, eq), v.substr(eq + 1));
      } else if (a == "--out") {
        out = v;
      } else {
        std::fprintf(stderr, "error: unknown option %s (see --help)\n", a.c_str());
        return 2;
      }
    } catch (const std::exception&) {
      std::fprintf(stderr, "error: bad value '%s' for %s (see --help)\n", v.c_str(), a.c_str());
      return 2;
    }
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
