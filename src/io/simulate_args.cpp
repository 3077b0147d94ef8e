// The command line of evidential_slam_simulate. See simulate_args.h.
#include "evidential_slam/io/simulate_args.h"

#include <memory>
#include <sstream>

#include "evidential_slam/io/command_line.h"

namespace evidential_slam {
namespace io {
namespace {

std::string optionName(const char* field) {
  std::string name = std::string("--") + field;
  for (char& c : name) c = c == '_' ? '-' : c;
  return name;
}

std::string defaultText(const GridmapSimulatorField& field) {
  std::ostringstream out;
  std::visit(
      [&](auto* value) {
        using T = std::decay_t<decltype(*value)>;
        if constexpr (std::is_same_v<T, bool>) {
          out << (*value ? "true" : "false");
        } else if constexpr (std::is_same_v<T, std::string>) {
          out << (value->empty() ? "none" : *value);
        } else {
          out << *value;
        }
      },
      field.value);
  return out.str();
}

// Stores `text` into the field; false with `why` when it does not parse.
bool setField(const GridmapSimulatorField& field, const std::string& text, std::string* why) {
  const std::string option = optionName(field.name);
  return std::visit(
      [&](auto* value) {
        using T = std::decay_t<decltype(*value)>;
        if constexpr (std::is_same_v<T, std::string>) {
          *value = text;
          return true;
        } else if constexpr (std::is_same_v<T, bool>) {
          if (text == "true" || text == "1") {
            *value = true;
          } else if (text == "false" || text == "0") {
            *value = false;
          } else {
            *why = option + " wants true or false, got '" + text + "'";
            return false;
          }
          return true;
        } else if constexpr (std::is_same_v<T, int>) {
          if (!parseNumber(text, value)) {
            *why = option + " wants an integer, got '" + text + "'";
            return false;
          }
          return true;
        } else {
          if (!parseNumber(text, value) || !std::isfinite(*value)) {
            *why = option + " wants a number, got '" + text + "'";
            return false;
          }
          return true;
        }
      },
      field.value);
}

// Declares every option of the simulator on a CommandLine writing into `o`.
// --origin-x/--origin-y given, --map-centered given: the first turns centring off unless the
// second is given too.
struct OriginFlags {
  bool origin_given = false;
  bool centered_given = false;
};

// The value's name in --help, by the field's type.
std::string valueName(const GridmapSimulatorField& field) {
  return std::visit(
      [](auto* value) -> std::string {
        using T = std::decay_t<decltype(*value)>;
        if constexpr (std::is_same_v<T, std::string>) return "FILE";
        if constexpr (std::is_same_v<T, bool>) return "true|false";
        if constexpr (std::is_same_v<T, int>) return "N";
        return "X";
      },
      field.value);
}

// The two required fields' fuller help.
const char* requiredHelp(const std::string& name) {
  if (name == "map") {
    return "map image (PNG, PGM...: white free, black wall, mid-grey unknown)\n"
           "with --resolution (and --origin-x/--origin-y), or a map_server .yaml";
  }
  return "route: one `x y` per line (m, map frame), '#' comments; the robot\n"
         "starts on the first waypoint facing the second, turns toward each\n"
         "next one (in place when it is more than 17 degrees off) and drives at\n"
         "up to --linear-speed / --angular-speed; the run ends at the last";
}

std::unique_ptr<CommandLine> simulateCommandLine(const std::string& program, SimulateOptions* o,
                                                 OriginFlags* origin) {
  auto cl = std::make_unique<CommandLine>(
      "Usage: " + program +
          " --map MAP --waypoints FILE --out SIM.rawlog [options]\n"
          "\n"
          "Simulates a differential robot with a planar laser on a grid map, like MRPT's\n"
          "GridmapNavSimul, and writes what it senses as an MRPT rawlog (Actions/SensoryFrame:\n"
          "odometry increment + one CObservation2DRangeScan per scan) plus the true pose of "
          "every\n"
          "scan to SIM.rawlog.GT.txt (`t x y phi` per line). The same seed gives the same files.\n"
          "Feed them to the offline runner:\n"
          "  evidential_slam_offline --rawlog SIM.rawlog --ground-truth SIM.rawlog.GT.txt --out "
          "DIR",
      "Noise: each return gets N(0, range-noise^2) (also the rawlog's stdError); each ray is\n"
      "cast bearing-noise off its nominal bearing. Each odometry increment (dx, dy, dth between\n"
      "scans, robot frame, d = its length) gets N(0, (odometry-noise-xy d)^2) on x and y and\n"
      "N(0, (odometry-noise-theta |dth| + odometry-noise-theta-per-m d)^2) on the heading.\n"
      "Ranges are MRPT ray casts, quantised to 0.8 cell along the ray.\n"
      "\n"
      "Exit status: 0 done, 1 bad usage or parameter value, 2 unreadable input or unwritable\n"
      "output.");
  const std::string required = "Required";
  const std::string faults = "Faults";
  const std::string other = "Other";
  const std::string settings =
      "Every simulator setting (also a private ROS parameter of gridmap_simulator, with '_' for "
      "'-'; --origin-x / --origin-y turn --map-centered off; default in brackets)";
  cl->option("--out", "FILE", "rawlog to write (gzip); the ground truth goes to FILE.GT.txt",
             [o](const std::string& v) { o->out = v; })
      ->group(required);
  cl->option("--kidnap", "T,DX,DY,DTH",
             "at sim time T (s) the true pose jumps by DX, DY (m, map frame) and\n"
             "DTH (rad); the odometry does not see it",
             [o](const std::string& value) {
               std::vector<double> v;
               if (!parseNumberList(value, 4, 4, &v)) {
                 throw UsageError("--kidnap wants T,DX,DY,DTH (four numbers)");
               }
               o->config.kidnap_time = v[0];
               o->config.kidnap_dx = v[1];
               o->config.kidnap_dy = v[2];
               o->config.kidnap_dtheta = v[3];
             })
      ->group(faults);
  cl->option("--moving-object", "T0,T1,BEARING_MIN,BEARING_MAX,DISTANCE",
             "during sim time [T0, T1] every ray with bearing in\n"
             "[BEARING_MIN, BEARING_MAX] (rad, laser frame, 0 = ahead, + = left)\n"
             "reads DISTANCE m (+ range noise)",
             [o](const std::string& value) {
               std::vector<double> v;
               if (!parseNumberList(value, 5, 5, &v)) {
                 throw UsageError(
                     "--moving-object wants T0,T1,BEARING_MIN,BEARING_MAX,DISTANCE (five numbers)");
               }
               o->config.moving_object_start = v[0];
               o->config.moving_object_end = v[1];
               o->config.moving_object_bearing_min = v[2];
               o->config.moving_object_bearing_max = v[3];
               o->config.moving_object_distance = v[4];
             })
      ->group(faults);
  cl->option("--truth-scans", "FILE",
             "also write per scan the true pose, the laser pose, the ranges and\n"
             "the object (--objects) each ray ended on (-1: a wall), for scoring",
             [o](const std::string& v) { o->truth_scans = v; })
      ->group(other);
  cl->flag("-q,--quiet", "no summary", [o] { o->quiet = true; })->group(other);
  // Every GridmapSimulatorConfig field: --name ('_' written '-'), its help and default.
  const std::vector<GridmapSimulatorField> fields = gridmapSimulatorFields(&o->config);
  GridmapSimulatorConfig defaults_config;
  const std::vector<GridmapSimulatorField> defaults = gridmapSimulatorFields(&defaults_config);
  for (size_t i = 0; i < fields.size(); ++i) {
    const GridmapSimulatorField field = fields[i];
    const std::string name = field.name;
    const bool is_required = name == "map" || name == "waypoints";
    CLI::Option* opt =
        cl->option(optionName(field.name), is_required ? "FILE" : valueName(field),
                   is_required ? requiredHelp(name)
                               : std::string(field.help) + " [" + defaultText(defaults[i]) + "]",
                   [origin, field, name](const std::string& v) {
                     std::string why;
                     if (!setField(field, v, &why)) throw UsageError(why);
                     if (name == "origin_x" || name == "origin_y") origin->origin_given = true;
                     if (name == "map_centered") origin->centered_given = true;
                   });
    opt->group(is_required ? required : settings);
  }
  return cl;
}

}  // namespace

std::string simulateUsage(const std::string& program) {
  SimulateOptions scratch;
  OriginFlags origin;
  return simulateCommandLine(program, &scratch, &origin)->help();
}

bool parseSimulateArgs(const std::vector<std::string>& args, SimulateOptions* o, bool* help,
                       std::string* error) {
  OriginFlags origin;
  if (!simulateCommandLine("evidential_slam_simulate", o, &origin)->parse(args, help, error)) {
    return false;
  }
  if (*help) return true;
  if (origin.origin_given && !origin.centered_given) o->config.map_centered = false;
  auto bad = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (o->config.map.empty()) return bad("--map is required");
  if (o->config.waypoints.empty()) return bad("--waypoints is required");
  if (o->out.empty()) return bad("--out is required");
  std::string why;
  if (!o->config.isValid(&why)) return bad(why);
  return true;
}

}  // namespace io
}  // namespace evidential_slam
