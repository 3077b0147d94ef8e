// The parameter table (parameters.def) as data: each parameter's description, setting a parameter
// from text (YAML files, --param NAME=VALUE, ROS parameters all go through it) and range checks.
// The visitor over a config's fields is in parameter_rows.h. ROS-free; ros/params.h binds the
// same rows to the parameter server and dynamic_reconfigure.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "evidential_slam/core/config.h"
#include "evidential_slam/core/conflict_alarm.h"
#include "evidential_slam/core/localization/localization_config.h"
#include "evidential_slam/core/parameter_fields/session.h"

namespace evidential_slam {

enum class ParameterScope { runtime, startup };

// One row of the table, without its field.
struct ParameterSpec {
  const char* name;
  const char* type;  // "int", "double", "bool" or "std::string"
  double min;        // valid range (numbers only), inclusive
  double max;
  const char* unit;
  ParameterScope scope;
  const char* meaning;
};

// What both front ends do around the SLAM engine (session/): the order of scans, and the map files
// written by the offline runner's --out and the node's ~save_map.
struct SessionConfig {
  SessionConfig();  // the table's defaults
  ES_SESSION_FIELDS

  bool isValid(std::string* why) const;
};

// Every parameter the offline runner and the node share: the SLAM's, the conflict alarm's, the
// session's and localization's. The node's own parameters are ros/params.h's.
struct Parameters {
  SlamConfig slam;
  ConflictAlarmConfig conflict_alarm;
  SessionConfig session;
  LocalizationConfig localization;

  bool isValid(std::string* why) const;
};

// The rows of the shared parameters, in table order.
std::vector<ParameterSpec> sharedParameterSpecs();
// Names of the parameters only the ROS node reads (frames, publishing, ...): a config file shared
// by both front ends may hold them, and the offline runner passes over them.
bool isNodeParameter(const std::string& name);

// The one bound on a laser's declared range noise (the beam models' work grows with it): the
// table's largest laser_range_sigma, in m. The node's laser_range_sigma is range-checked to it and
// a rawlog's declared noise (stdError) is clamped to it, both through clampDeclaredRangeSigma
// (not finite or not positive: 0, unknown).
double maxDeclaredRangeSigma();
float clampDeclaredRangeSigma(double sigma);

// Parses `text` into `field` and checks it against `spec`'s range. False with a one-line `why`
// (naming the parameter) for a value of the wrong type or out of range; the field is unchanged
// then. Numbers: whole-string decimal; switches: true/false/1/0.
bool parseParameter(const ParameterSpec& spec, const std::string& text, int* field,
                    std::string* why);
bool parseParameter(const ParameterSpec& spec, const std::string& text, double* field,
                    std::string* why);
bool parseParameter(const ParameterSpec& spec, const std::string& text, bool* field,
                    std::string* why);
bool parseParameter(const ParameterSpec& spec, const std::string& text, std::string* field,
                    std::string* why);

// True when `value` is within `spec`'s range (always for switches and strings); else `why`.
bool inRange(const ParameterSpec& spec, double value, std::string* why);
bool inRange(const ParameterSpec& spec, int value, std::string* why);
bool inRange(const ParameterSpec& spec, bool value, std::string* why);
bool inRange(const ParameterSpec& spec, const std::string& value, std::string* why);

// Sets one shared parameter by name from text. False with a one-line reason for an unknown name
// (node parameters included: use isNodeParameter to pass over them) or a bad value.
bool setParameter(const std::string& name, const std::string& value, Parameters* params,
                  std::string* why);

// A parameter's value as the text its parser reads back (doubles: the shortest exact text).
std::string valueText(int v);
std::string valueText(double v);
std::string valueText(bool v);
std::string valueText(const std::string& v);

// Every shared parameter's value as text (for summaries and map files), in table order.
std::vector<std::pair<std::string, std::string>> parameterValues(const Parameters& p);

}  // namespace evidential_slam
