// The command line of evidential_slam_simulate. See simulate_args.h.
#include "evidential_slam/io/simulate_args.h"

#include <cmath>
#include <sstream>

#include "evidential_slam/io/command_line.h"

namespace evidential_slam {
namespace io {
namespace {

// "a,b,c" -> numbers; false unless exactly `count` finite numbers.
bool parseList(const std::string& text, size_t count, std::vector<double>* out) {
  out->clear();
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item, ',')) {
    double v = 0.0;
    if (!parseNumber(item, &v) || !std::isfinite(v)) return false;
    out->push_back(v);
  }
  return out->size() == count && (text.empty() || text.back() != ',');
}

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

}  // namespace

std::string simulateUsage(const std::string& program) {
  std::ostringstream u;
  u << "Usage: " << program
    << " --map MAP --waypoints FILE --out SIM.rawlog [options]\n"
       "\n"
       "Simulates a differential robot with a planar laser on a grid map, like MRPT's\n"
       "GridmapNavSimul, and writes what it senses as an MRPT rawlog (Actions/SensoryFrame:\n"
       "odometry increment + one CObservation2DRangeScan per scan) plus the true pose of every\n"
       "scan to SIM.rawlog.GT.txt (`t x y phi` per line). The same seed gives the same files.\n"
       "Feed them to the offline runner:\n"
       "  evidential_slam_offline --rawlog SIM.rawlog --ground-truth SIM.rawlog.GT.txt --out DIR\n"
       "\n"
       "Required:\n"
       "  --map FILE          map image (PNG, PGM...: white free, black wall, mid-grey unknown)\n"
       "                      with --resolution (and --origin-x/--origin-y), or a map_server "
       ".yaml\n"
       "  --waypoints FILE    route: one `x y` per line (m, map frame), '#' comments; the robot\n"
       "                      starts on the first waypoint facing the second, turns toward each\n"
       "                      next one (in place when it is more than 17 degrees off) and drives "
       "at\n"
       "                      up to --linear-speed / --angular-speed; the run ends at the last\n"
       "  --out FILE          rawlog to write (gzip); the ground truth goes to FILE.GT.txt\n"
       "\n"
       "Faults:\n"
       "  --kidnap T,DX,DY,DTH\n"
       "                      at sim time T (s) the true pose jumps by DX, DY (m, map frame) and\n"
       "                      DTH (rad); the odometry does not see it\n"
       "  --moving-object T0,T1,BEARING_MIN,BEARING_MAX,DISTANCE\n"
       "                      during sim time [T0, T1] every ray with bearing in\n"
       "                      [BEARING_MIN, BEARING_MAX] (rad, laser frame, 0 = ahead, + = left)\n"
       "                      reads DISTANCE m (+ range noise)\n"
       "\n"
       "Other:\n"
       "  --truth-scans FILE  also write per scan the true pose, the laser pose, the ranges and\n"
       "                      the object (--objects) each ray ended on (-1: a wall), for scoring\n"
       "  --quiet             no summary\n"
       "  -h, --help          this text\n"
       "\n"
       "Every simulator setting (also a private ROS parameter of gridmap_simulator, with '_' for\n"
       "'-'). --origin-x / --origin-y turn --map-centered off. Default in brackets:\n";
  GridmapSimulatorConfig defaults;
  for (const auto& field : gridmapSimulatorFields(&defaults)) {
    std::string option = optionName(field.name);
    if (option.size() < 28) option.resize(28, ' ');
    u << "  " << option << " " << field.help << " [" << defaultText(field) << "]\n";
  }
  u << "\n"
       "Noise: each return gets N(0, range-noise^2) (also the rawlog's stdError); each ray is\n"
       "cast bearing-noise off its nominal bearing. Each odometry increment (dx, dy, dth between\n"
       "scans, robot frame, d = its length) gets N(0, (odometry-noise-xy d)^2) on x and y and\n"
       "N(0, (odometry-noise-theta |dth| + odometry-noise-theta-per-m d)^2) on the heading.\n"
       "Ranges are MRPT ray casts, quantised to 0.8 cell along the ray.\n"
       "\n"
       "Exit status: 0 done, 1 bad usage or parameter value, 2 unreadable input or unwritable\n"
       "output.\n";
  return u.str();
}

bool parseSimulateArgs(const std::vector<std::string>& args, SimulateOptions* o, bool* help,
                       std::string* error) {
  *help = false;
  auto bad = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  const std::vector<GridmapSimulatorField> fields = gridmapSimulatorFields(&o->config);
  bool origin_given = false, centered_given = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const CommandLineArg arg = splitArg(args[i]);
    const std::string& flag = arg.flag;
    std::string value = arg.value;
    const bool has_inline = arg.has_value;
    if (flag == "-h" || flag == "--help") {
      *help = true;
      return true;
    }
    if (flag == "--quiet" || flag == "-q") {
      if (has_inline) return bad("--quiet takes no value");
      o->quiet = true;
      continue;
    }
    const GridmapSimulatorField* field = nullptr;
    for (const auto& f : fields) {
      if (flag == optionName(f.name)) field = &f;
    }
    if (!field && flag != "--out" && flag != "--kidnap" && flag != "--moving-object" &&
        flag != "--truth-scans") {
      return bad("unknown option '" + args[i] + "'");
    }
    if (!has_inline) {
      if (i + 1 >= args.size()) return bad(flag + " needs a value");
      value = args[++i];
    }
    std::vector<double> v;
    if (flag == "--out") {
      o->out = value;
    } else if (flag == "--truth-scans") {
      o->truth_scans = value;
    } else if (flag == "--kidnap") {
      if (!parseList(value, 4, &v)) return bad("--kidnap wants T,DX,DY,DTH (four numbers)");
      o->config.kidnap_time = v[0];
      o->config.kidnap_dx = v[1];
      o->config.kidnap_dy = v[2];
      o->config.kidnap_dtheta = v[3];
    } else if (flag == "--moving-object") {
      if (!parseList(value, 5, &v)) {
        return bad("--moving-object wants T0,T1,BEARING_MIN,BEARING_MAX,DISTANCE (five numbers)");
      }
      o->config.moving_object_start = v[0];
      o->config.moving_object_end = v[1];
      o->config.moving_object_bearing_min = v[2];
      o->config.moving_object_bearing_max = v[3];
      o->config.moving_object_distance = v[4];
    } else {
      std::string why;
      if (!setField(*field, value, &why)) return bad(why);
      const std::string name = field->name;
      origin_given = origin_given || name == "origin_x" || name == "origin_y";
      centered_given = centered_given || name == "map_centered";
    }
  }
  if (origin_given && !centered_given) o->config.map_centered = false;
  if (o->config.map.empty()) return bad("--map is required");
  if (o->config.waypoints.empty()) return bad("--waypoints is required");
  if (o->out.empty()) return bad("--out is required");
  std::string why;
  if (!o->config.isValid(&why)) return bad(why);
  return true;
}

}  // namespace io
}  // namespace evidential_slam
