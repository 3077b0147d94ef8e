#!/usr/bin/env python3
"""The parameter table (include/evidential_slam/core/parameters.def) for Python: rows, and the
Markdown tables of the docs made from them.

  scripts/parameter_table.py markdown          print the tables
  scripts/parameter_table.py update FILE...    rewrite the generated blocks of FILEs
  scripts/parameter_table.py check FILE... [--junit XML]
                                               fail when a generated block differs
  scripts/parameter_table.py fields DIR        write DIR/<list>.h, each list's field declarations

The field headers let a Config struct declare its fields without including the table: they name
each field's type and member only, and a file is rewritten only when that changes, so editing a
row's default, range or meaning recompiles the few files that expand the table, not every user
of the struct (the defaults are set by the struct's constructor, defined next to the table).

A generated block lies between `<!-- BEGIN GENERATED: NAME -->` and `<!-- END GENERATED: NAME -->`,
NAME a key of BLOCKS (e.g. `basic-parameters`: the SLAM node's basic rows, `parameters`: all of
its lists, basic rows in bold, `explorer-parameters`: the explorer's,
`monitor-parameters`: exploration_monitor's); a file holds one or more. cfg/EvidentialSlam.cfg imports this module too.
"""
import csv
import io
import os
import re
import sys
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.realpath(__file__))
DEF_FILE = os.path.join(HERE, "..", "include", "evidential_slam", "core", "parameters.def")
BEGIN = "<!-- BEGIN GENERATED: %s -->"
END = "<!-- END GENERATED: %s -->"

# Lists in the order the docs show them, with their heading.
# The SLAM node's lists in the order dynamic_reconfigure's .cfg groups them, with their heading.
SLAM_GROUPS = [
    ("FILTER", "filter", "Particle filter"),
    ("SENSOR_MODEL", "sensor_model", "Sensor models"),
    ("MOTION_MODEL", "motion_model", "Motion model"),
    ("SCAN_MATCHER", "scan_matcher", "Scan matching"),
    ("LONG_STEP", "long_step", "After a long odometry step"),
    ("CONFLICT_ALARM", "conflict_alarm", "Conflict alarm"),
    ("SESSION", "session", "Scan order and saved maps"),
    ("LOCALIZATION", "localization", "Localization mode"),
    ("NODE", "node", "ROS node only"),
]
# Localization on a saved map, documented in docs/localization.md (and in docs/parameters.md).
LOCALIZATION_KEYS = ("LOCALIZATION",)
# The map fusion node, documented in docs/fusion.md.
FUSION_GROUPS = [("MAP_FUSION", "map_fusion", "Map fusion node (map_fusion)")]
# The explorer's lists (core/exploration, the explorer node), documented in docs/exploration.md.
EXPLORER_GROUPS = [
    ("EXPLORER_CELL", "cells", "Cell classes"),
    ("EXPLORER_GOAL", "goals", "Frontiers and goals"),
    ("EXPLORER", "explorer", "Replanning and blacklisting"),
    ("EXPLORER_PLANNER", "planner", "Path planner"),
    ("EXPLORER_PURSUIT", "pursuit", "Pure pursuit"),
    ("EXPLORER_NODE", "explorer_node", "Explorer node only"),
]
# exploration_monitor (the measuring harness of explore.launch), documented in docs/exploration.md.
MONITOR_GROUPS = [("EXPLORATION_MONITOR", "exploration_monitor", "exploration_monitor")]
LOCALIZATION_GROUPS = [g for g in SLAM_GROUPS if g[0] in LOCALIZATION_KEYS]
# The SLAM node's basic rows (tier `basic`) in one table: the README's; docs/parameters.md has
# every row of the SLAM node's lists, basic and advanced.
BASIC_GROUPS = [("BASIC", "basic", "Basic parameters")]
BLOCKS = {"basic-parameters": BASIC_GROUPS, "parameters": SLAM_GROUPS,
          "localization-parameters": LOCALIZATION_GROUPS,
          "fusion-parameters": FUSION_GROUPS, "explorer-parameters": EXPLORER_GROUPS,
          "monitor-parameters": MONITOR_GROUPS}
FIELDS = ["ctx", "name", "member", "type", "default", "min", "max", "unit", "scope", "tier",
          "meaning"]


class Row(dict):
    __getattr__ = dict.__getitem__


def rows(path=DEF_FILE):
    """Every row of the table, in file order, with its list ('group')."""
    result, group = [], None
    with open(path, encoding="utf-8") as f:
        for line in f:
            m = re.match(r"#define ES_(\w+)_PARAMETERS\(X, ctx\)", line)
            if m:
                group = m.group(1)
                continue
            m = re.match(r"\s*X\((.*)\)\s*\\?\s*$", line)
            if not m or group is None:
                continue
            cells = next(csv.reader(io.StringIO(m.group(1)), skipinitialspace=True))
            if len(cells) != len(FIELDS):
                raise ValueError("%s: a row with %d cells: %s" % (path, len(cells), line))
            row = Row(zip(FIELDS, [c.strip() for c in cells]))
            row["group"] = group
            if row.tier not in ("basic", "advanced"):
                raise ValueError("%s: tier must be basic or advanced: %s" % (path, line))
            result.append(row)
    return result


def python_value(row, text):
    t = row.type
    if t == "bool":
        return text == "true"
    if t == "int":
        return int(text)
    if t == "double":
        return float(text)
    return text.strip('"')


def default_text(row):
    if row.type == "std::string":
        return "`%s`" % row.default.strip('"')
    return "`%s`" % row.default


def range_text(row):
    if row.type in ("bool", "std::string"):
        return ""
    return "%s – %s" % (row.min, row.max)


def slam_rows(key, all_rows):
    """The rows of list `key`; BASIC: the basic rows of every SLAM node list."""
    if key == "BASIC":
        slam = [g[0] for g in SLAM_GROUPS]
        return [r for r in all_rows if r.group in slam and r.tier == "basic"]
    return [r for r in all_rows if r.group == key]


def markdown(groups=SLAM_GROUPS):
    out = []
    all_rows = rows()
    for key, _, title in groups:
        group = slam_rows(key, all_rows)
        if not group:
            continue
        out.append("**%s**\n" % title)
        out.append("| name | type | default | range | unit | meaning |")
        out.append("|---|---|---|---|---|---|")
        for r in group:
            meaning = r.meaning + ("" if r.scope == "runtime" else " *(start-up only)*")
            name = ("**`%s`**" if r.tier == "basic" and key != "BASIC" else "`%s`") % r.name
            out.append("| %s | %s | %s | %s | %s | %s |" % (
                name, r.type.replace("std::", ""), default_text(r), range_text(r), r.unit,
                meaning.replace("|", "\\|")))
        out.append("")
    return "\n".join(out).rstrip("\n") + "\n"


def replace_blocks(text):
    """The text with every generated block rewritten; None when it holds none."""
    found = False
    for name, groups in BLOCKS.items():
        begin, end = BEGIN % name, END % name
        if begin not in text or end not in text:
            continue
        found = True
        head, rest = text.split(begin, 1)
        _, tail = rest.split(end, 1)
        text = head + begin + "\n" + markdown(groups) + end + tail
    return text if found else None


def field_headers(all_rows):
    """{file name: text} of every list's field header."""
    headers = {}
    for group in dict.fromkeys(r.group for r in all_rows):
        decls = ["  %s %s;" % (r.type, r.member) for r in all_rows if r.group == group]
        headers[group.lower() + ".h"] = (
            "// Generated by scripts/parameter_table.py from parameters.def: do not edit.\n"
            "// The fields of list ES_%s_PARAMETERS (their defaults: the struct's constructor).\n"
            "#pragma once\n#include <string>\n\n#define ES_%s_FIELDS \\\n%s\n"
            % (group, group, " \\\n".join(decls)))
    return headers


def write_fields(directory):
    os.makedirs(directory, exist_ok=True)
    for name, text in field_headers(rows()).items():
        path = os.path.join(directory, name)
        try:
            with open(path, encoding="utf-8") as f:
                if f.read() == text:
                    continue
        except FileNotFoundError:
            pass
        with open(path + ".tmp", "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(path + ".tmp", path)
    return 0


def main(argv):
    if not argv or argv[0] not in ("markdown", "update", "check", "fields"):
        print(__doc__)
        return 1
    if argv[0] == "markdown":
        sys.stdout.write(markdown())
        return 0
    if argv[0] == "fields":
        return write_fields(argv[1])
    junit = None
    files = []
    args = argv[1:]
    while args:
        a = args.pop(0)
        if a == "--junit":
            junit = args.pop(0)
        else:
            files.append(a)
    failures = []
    # Every list of the table is documented by some block.
    listed = {key for groups in BLOCKS.values() for key, _, _ in groups}
    for group in sorted({r.group for r in rows()} - listed):
        failures.append("%s: list ES_%s_PARAMETERS is in no generated block (BLOCKS)"
                        % (os.path.relpath(DEF_FILE), group))
    for path in files:
        with open(path, encoding="utf-8") as f:
            text = f.read()
        new = replace_blocks(text)
        if new is None:
            failures.append("%s: no generated parameter block" % path)
        elif argv[0] == "update":
            if new != text:
                with open(path, "w", encoding="utf-8") as f:
                    f.write(new)
        elif new != text:
            failures.append("%s: the parameter tables differ from the table "
                            "(run scripts/parameter_table.py update %s)" % (path, path))
    for f in failures:
        print("error: " + f)
    if junit:
        suite = ET.Element("testsuite", name="parameter_tables", tests=str(len(files)),
                           failures=str(len(failures)), errors="0")
        for path in files:
            case = ET.SubElement(suite, "testcase", classname="parameter_tables",
                                 name=os.path.basename(path))
            for f in failures:
                if f.startswith(path + ":"):
                    ET.SubElement(case, "failure", message=f)
        os.makedirs(os.path.dirname(os.path.abspath(junit)), exist_ok=True)
        ET.ElementTree(suite).write(junit, encoding="utf-8", xml_declaration=True)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
