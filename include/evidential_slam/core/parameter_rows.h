// The parameter table's rows, expanded: include this only where the table is read row by row
// (the structs' defaults, range checks, visitors, specs). Struct headers declare their fields
// through the generated parameter_fields/*.h instead, so editing a row's default, range or
// meaning recompiles only the files that include this one.
#pragma once

#include "evidential_slam/core/parameters.def"
#include "evidential_slam/core/parameters.h"

namespace evidential_slam {

// Visits one row: visit(spec, field).
#define ES_VISIT_PARAMETER(ctx, name, member, type, def, min, max, unit, scope, tier, meaning) \
  visit(::evidential_slam::ParameterSpec{#name, #type, static_cast<double>(min),               \
                                         static_cast<double>(max), unit,                       \
                                         ::evidential_slam::ParameterScope::scope, meaning},   \
        (ctx).member);

// Range checks of every row of `Config`'s list (its isValid builds on it): the first failure's
// message goes to `why`.
#define ES_CHECK_PARAMETER_RANGE(ctx, name, member, type, def, min, max, unit, scope, tier,  \
                                 meaning)                                                    \
  ok = ok && ::evidential_slam::inRange(                                                     \
                 ::evidential_slam::ParameterSpec{                                           \
                     #name, #type, static_cast<double>(min), static_cast<double>(max), unit, \
                     ::evidential_slam::ParameterScope::scope, meaning},                     \
                 (ctx).member, why);

template <typename SharedParameters, typename Visitor>
void forEachSharedParameter(SharedParameters& p, Visitor&& visit) {
  ES_SLAM_CONFIG_PARAMETERS(ES_VISIT_PARAMETER, p.slam)
  ES_CONFLICT_ALARM_PARAMETERS(ES_VISIT_PARAMETER, p.conflict_alarm)
  ES_SESSION_PARAMETERS(ES_VISIT_PARAMETER, p.session)
  ES_LOCALIZATION_PARAMETERS(ES_VISIT_PARAMETER, p.localization)
}

}  // namespace evidential_slam
