#!/usr/bin/env python3
"""The rooms' one-way doors, checked with the include paths each room's library compiles with.

  check_rooms.py --compiler CXX --rooms BUILD/rooms --include REPO/include [--junit XML]

For every room R and every header H of another room: H must be found from R when R may use H's
room (core <- io <- session <- ros) and must not be found otherwise. The include paths are the
ones CMake computed for R's library (BUILD/rooms/R.includes, cmake/Rooms.cmake), so the check
fails when a room's CMakeLists.txt links or names an include path against the arrows.

Also: no header reaches the parameter table (core/parameters.def) except the parameter_rows.h
headers, which only .cpp files include. Struct headers name their fields through the generated
parameter_fields/*.h, so editing a row's default recompiles only the files that read the table.
"""
import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

ROOMS = ["core", "io", "session", "ros"]
MAY_USE = {room: set(ROOMS[: i + 1]) for i, room in enumerate(ROOMS)}


def headers(include_root, room):
    base = os.path.join(include_root, "evidential_slam", room)
    found = []
    for d, _, names in os.walk(base):
        found += [os.path.relpath(os.path.join(d, n), include_root)
                  for n in names if n.endswith(".h")]
    return sorted(found)


def preprocess(compiler, includes, header, workdir):
    probe = os.path.join(workdir, "probe.cpp")
    with open(probe, "w") as f:
        f.write('#include "%s"\n' % header)
    cmd = [compiler, "-std=c++17", "-E", "-o", os.devnull, probe] + ["-I" + i for i in includes]
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    return r.returncode, r.stderr


def table_reach(include_root):
    """Headers (other than the parameter_rows.h ones) that include the table, directly or not."""
    graph = {}
    for d, _, names in os.walk(os.path.join(include_root, "evidential_slam")):
        for n in names:
            if n.endswith(".h"):
                path = os.path.join(d, n)
                with open(path, encoding="utf-8") as f:
                    graph[os.path.relpath(path, include_root)] = re.findall(
                        r'^\s*#\s*include\s+"(evidential_slam/[^"]+)"', f.read(), re.M)
    table = "evidential_slam/core/parameters.def"
    reaches, problems = {}, []

    def reach(header, stack=()):
        if header == table:
            return True
        if header not in reaches:
            reaches[header] = header not in stack and any(
                reach(h, stack + (header,)) for h in graph.get(header, []))
        return reaches[header]

    for header in sorted(graph):
        if not header.endswith("parameter_rows.h") and reach(header):
            problems.append("%s reaches parameters.def: a row's default would recompile every "
                            "file that includes it (include the generated parameter_fields/*.h; "
                            "expand rows in a .cpp through parameter_rows.h)" % header)
    return problems


def main(argv):
    args = dict(zip(argv[1::2], argv[2::2]))
    compiler, rooms_dir, include_root = args["--compiler"], args["--rooms"], args["--include"]
    problems, checked = [], 0
    with tempfile.TemporaryDirectory() as workdir:
        for room in ROOMS:
            with open(os.path.join(rooms_dir, room + ".includes")) as f:
                includes = [line.strip() for line in f if line.strip()]
            for other in ROOMS:
                if other == room:
                    continue
                names = headers(include_root, other)
                if other in MAY_USE[room]:
                    names = names[:1]  # reachable: one header shows the door is open
                for header in names:
                    checked += 1
                    rc, err = preprocess(compiler, includes, header, workdir)
                    missing = rc != 0 and "No such file" in err and header in err
                    if other in MAY_USE[room] and rc != 0:
                        problems.append("%s cannot include %s: %s" % (
                            room, header, err.strip().splitlines()[0] if err.strip() else rc))
                    elif other not in MAY_USE[room] and not missing:
                        problems.append("%s can include %s (against the arrows)" % (room, header))
    problems += table_reach(include_root)
    for p in problems:
        print(p)
    print("%d includes checked, %d wrong" % (checked, len(problems)))
    if "--junit" in args:
        suite = ET.Element("testsuite", name="rooms", tests="1",
                           failures=str(int(bool(problems))), errors="0")
        case = ET.SubElement(suite, "testcase", classname="rooms", name="one_way_doors")
        if problems:
            ET.SubElement(case, "failure", message="%d of %d includes wrong" % (
                len(problems), checked)).text = "\n".join(problems)
        os.makedirs(os.path.dirname(os.path.abspath(args["--junit"])), exist_ok=True)
        ET.ElementTree(suite).write(args["--junit"], encoding="utf-8", xml_declaration=True)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
