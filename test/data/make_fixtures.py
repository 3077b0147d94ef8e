#!/usr/bin/env python3
"""Regenerates the committed test fixtures of test/data/ (Python standard library, MRPT CLI tools).

What it makes and why:
  sim_map.png       a 16 m x 12 m two-room floor plan at 0.05 m/pixel, drawn here (black = wall).
  sim.rawlog        Actions/SensoryFrame rawlog: scans simulated on that map by MRPT's
                    `simul-gridmap` (181 rays over 180 deg, label LASER) along a loop through both
                    rooms, with noisy, biased odometry increments (seeded; odometry alone has
                    ~0.7 m ATE RMSE).
  sim_obs.rawlog    the same log in the observation-only format (scan, then CObservationOdometry).
  sim.GT.txt        the true pose of every scan, `t x y phi`, same timestamps as the scans.
  sim_first_half.evmap  the map file of sim.rawlog's first 80 scans, written by
                    evidential_slam_offline (--preset sim, K = 20, seed 3): the map the node
                    starts on in test/ros/slam_map_file.test. `--map-only` remakes just the map files
                    from the committed sim.rawlog (after a change of the map file's format).
  moved_box_day1.evmap  day 1 of test/ros/slam_map_file_moved.test: three laps of
                    moved_box_route.txt through sim_map.png's left room with the box of
                    moved_box_day1.objects, simulated by evidential_slam_simulate (0.2 s scans,
                    seed 1) and mapped by evidential_slam_offline (--preset sim, K = 20, seed 3,
                    update_min_distance 0.2 as in the test) with unbounded cells (flip_scans 0):
                    the box's day-2 place is free with full confidence (m(Θ) = 0), the case a
                    node without bounded confidence never changes. `--map-only` remakes it too.
The intermediate .gridmap.gz and pose list are written to a temporary directory.

simul-gridmap writes zero odometry increments and no MRPT tool converts between the two rawlog
formats, so those two steps are done by evidential_slam_fixture_tool (test/io/fixture_tool_main.cpp,
built by `catkin_make tests`), whose path is the first argument.

simul-gridmap stamps the scans with the wall clock while it runs and simulates one scan per pose
except the first, so the script remaps the stamps to start at 1000 s, 0.2 s apart on average
(`rawlog-edit --remap-timestamps`) and writes the ground truth from the scans' own stamps
(`rawlog-edit --list-timestamps`). The odometry noise is seeded; the laser noise and the stamps
come from simul-gridmap's unseeded generator and the wall clock, so regenerating changes the
rawlog's bytes, not its character.

Usage: test/data/make_fixtures.py [--map-only] FIXTURE_TOOL [OUT_DIR]   (default OUT_DIR: the
  directory of this script; evidential_slam_offline is looked for beside FIXTURE_TOOL)
  e.g. test/data/make_fixtures.py ~/ws/devel/lib/evidential_slam/evidential_slam_fixture_tool
Needs: mrpt-apps (image2gridmap, simul-gridmap, rawlog-edit) on PATH.
"""
import math
import os
import struct
import subprocess
import sys
import tempfile
import zlib

RESOLUTION = 0.05  # m per pixel
WIDTH_M, HEIGHT_M = 16.0, 12.0
W, H = int(WIDTH_M / RESOLUTION), int(HEIGHT_M / RESOLUTION)
STEP_M = 0.25  # distance between simulated poses
SCAN_PERIOD_S = 0.2
RAYS = 181


def draw_map():
    """Returns rows of grey values (row 0 = top of the image = highest y), 255 free, 0 wall."""
    img = [[255] * W for _ in range(H)]

    def box(x0, y0, x1, y1):
        """Fills the metric box [x0, x1] x [y0, y1] (map frame, origin at the image centre)."""
        c0 = int(round((x0 + WIDTH_M / 2) / RESOLUTION))
        c1 = int(round((x1 + WIDTH_M / 2) / RESOLUTION))
        r0 = int(round((HEIGHT_M / 2 - y1) / RESOLUTION))
        r1 = int(round((HEIGHT_M / 2 - y0) / RESOLUTION))
        for r in range(max(r0, 0), min(r1, H)):
            for c in range(max(c0, 0), min(c1, W)):
                img[r][c] = 0

    t = 0.15  # wall thickness
    # Outer walls.
    box(-8.0, -6.0, 8.0, -6.0 + t)
    box(-8.0, 6.0 - t, 8.0, 6.0)
    box(-8.0, -6.0, -8.0 + t, 6.0)
    box(8.0 - t, -6.0, 8.0, 6.0)
    # Dividing wall at x = 0 with two doors (y in [-4.5, -3] and [2.5, 4]).
    box(-t / 2, -6.0, t / 2, -4.5)
    box(-t / 2, -3.0, t / 2, 2.5)
    box(-t / 2, 4.0, t / 2, 6.0)
    # Left room: a pillar, an L-shaped counter, a cabinet against the wall.
    box(-5.0, -0.4, -4.4, 0.2)
    box(-7.85, 3.0, -6.0, 3.3)
    box(-6.3, 3.3, -6.0, 5.85)
    box(-3.0, -5.85, -1.8, -5.3)
    # Right room: two pillars, a short wall stub, a slanted shelf made of steps.
    box(3.0, 0.5, 3.5, 1.0)
    box(5.5, -2.0, 6.1, -1.4)
    box(6.0, 3.0, 7.85, 3.25)
    for k in range(8):
        box(2.0 + 0.25 * k, -5.85 + 0.2 * k, 2.3 + 0.25 * k, -5.6 + 0.2 * k)
    return img


def write_png(path, rows):
    """8-bit greyscale PNG, written with zlib only (no imaging library needed)."""
    raw = b"".join(b"\x00" + bytes(r) for r in rows)

    def chunk(tag, data):
        return (struct.pack(">I", len(data)) + tag + data +
                struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", len(rows[0]), len(rows), 8, 0, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def trajectory():
    """Poses every STEP_M along a loop through both rooms, heading along the path."""
    waypoints = [(-6.0, -4.0), (-2.0, -4.0), (1.5, -3.75), (4.0, -3.5), (6.5, -3.5), (6.8, 0.0),
                 (5.0, 2.0), (2.0, 3.25), (-1.5, 3.25), (-4.0, 2.0), (-6.5, 1.5), (-6.8, -2.0),
                 (-5.5, -4.0), (-2.0, -4.0)]
    points = []
    for (x0, y0), (x1, y1) in zip(waypoints, waypoints[1:]):
        n = max(1, int(math.hypot(x1 - x0, y1 - y0) / STEP_M))
        for i in range(n):
            a = i / n
            points.append((x0 + a * (x1 - x0), y0 + a * (y1 - y0)))
    points.append(waypoints[-1])
    poses = []
    for i, (x, y) in enumerate(points):
        j = min(i + 1, len(points) - 1)
        k = max(j - 1, 0) if j == i else i
        phi = math.atan2(points[j][1] - points[k][1], points[j][0] - points[k][0])
        poses.append((x, y, phi))
    return poses


def run(*cmd):
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)


def make_map_file(offline, out_dir):
    """sim_first_half.evmap: the offline runner's map file of sim.rawlog's first 80 scans."""
    with tempfile.TemporaryDirectory() as tmp:
        run(offline, "--rawlog", os.path.join(out_dir, "sim.rawlog"), "--out", tmp, "--preset",
            "sim", "--particles", "20", "--seed", "3", "--threads", "2", "--max-scans", "80",
            "--quiet")
        target = os.path.join(out_dir, "sim_first_half.evmap")
        os.replace(os.path.join(tmp, "map.evmap"), target)
    print("wrote %s" % target)


def make_moved_box_map(offline, out_dir):
    """moved_box_day1.evmap: three laps of the left room with the box at its day-1 place."""
    simulate = os.path.join(os.path.dirname(offline), "evidential_slam_simulate")
    here = os.path.dirname(os.path.abspath(__file__))
    lap = [l for l in open(os.path.join(here, "moved_box_route.txt"))
           if l.strip() and not l.startswith("#")]
    with tempfile.TemporaryDirectory() as tmp:
        route = os.path.join(tmp, "route.txt")
        with open(route, "w") as f:
            f.writelines(lap + lap[1:] + lap[1:])
        rawlog = os.path.join(tmp, "day1.rawlog")
        run(simulate, "--map", os.path.join(here, "sim_map.png"), "--waypoints", route,
            "--objects", os.path.join(here, "moved_box_day1.objects"), "--scan-period", "0.2",
            "--seed", "1", "--out", rawlog, "--quiet")
        out = os.path.join(tmp, "out")
        run(offline, "--rawlog", rawlog, "--out", out, "--preset", "sim", "--particles", "20",
            "--seed", "3", "--threads", "2", "--param", "update_min_distance=0.2", "--param",
            "flip_scans=0", "--quiet")
        target = os.path.join(out_dir, "moved_box_day1.evmap")
        os.replace(os.path.join(out, "map.evmap"), target)
    print("wrote %s" % target)


def main():
    args = sys.argv[1:]
    map_only = "--map-only" in args
    args = [a for a in args if a != "--map-only"]
    if not args or not os.access(args[0], os.X_OK):
        sys.exit(__doc__)
    tool = os.path.abspath(args[0])
    offline = os.path.join(os.path.dirname(tool), "evidential_slam_offline")
    out_dir = os.path.abspath(args[1] if len(args) > 1 else os.path.dirname(__file__))
    os.makedirs(out_dir, exist_ok=True)
    if map_only:
        make_map_file(offline, out_dir)
        make_moved_box_map(offline, out_dir)
        return
    map_png = os.path.join(out_dir, "sim_map.png")
    write_png(map_png, draw_map())
    poses = trajectory()
    with tempfile.TemporaryDirectory() as tmp:
        grid = os.path.join(tmp, "sim_map.gridmap.gz")
        run("image2gridmap", "-i", map_png, "-r", str(RESOLUTION), "-o", grid, "-w")
        pose_file = os.path.join(tmp, "poses.txt")
        with open(pose_file, "w") as f:
            for i, (x, y, phi) in enumerate(poses):
                f.write("%d %.6f %.6f %.6f\n" % (i, x, y, phi))
        wall_clock = os.path.join(tmp, "wall_clock.rawlog")
        run("simul-gridmap", "-g", grid, "-p", pose_file, "-o", wall_clock, "-r", str(RAYS))
        # Remap the wall-clock stamps to 1000 s + SCAN_PERIOD_S * index.
        stamps_file = os.path.join(tmp, "stamps.txt")
        run("rawlog-edit", "-q", "-i", wall_clock, "--list-timestamps", "--text-file-output",
            stamps_file)
        stamps = [float(l.split()[0]) for l in open(stamps_file) if l.strip()]
        # Scans are simulated at poses[1:]; one stamp per scan.
        assert len(stamps) == len(poses) - 1, (len(stamps), len(poses))
        # Two affine remaps t' = a t + b (one would lose digits): shift the first stamp to 1 s (0 is
        # MRPT's invalid stamp), then
        # stretch the run to SCAN_PERIOD_S per scan on average and start at 1000 s. The spacing
        # stays as irregular as simul-gridmap's run was.
        shifted = os.path.join(tmp, "shifted.rawlog")
        run("rawlog-edit", "-q", "-w", "-i", wall_clock, "-o", shifted, "--remap-timestamps",
            "1;%.6f" % (1.0 - stamps[0]))
        scale = SCAN_PERIOD_S * (len(stamps) - 1) / max(stamps[-1] - stamps[0], 1e-6)
        stamped = os.path.join(tmp, "stamped.rawlog")
        run("rawlog-edit", "-q", "-w", "-i", shifted, "-o", stamped, "--remap-timestamps",
            "%.9f;%.9f" % (scale, 1000.0 - scale))
        run("rawlog-edit", "-q", "-i", stamped, "--list-timestamps", "--text-file-output",
            stamps_file)
        stamps = [float(l.split()[0]) for l in open(stamps_file) if l.strip()]
        gt = os.path.join(out_dir, "sim.GT.txt")
        with open(gt, "w") as f:
            f.write("# t x y phi: true pose of each scan of sim.rawlog (make_fixtures.py)\n")
            for t, (x, y, phi) in zip(stamps, poses[1:]):
                f.write("%.6f %.6f %.6f %.6f\n" % (t, x, y, phi))
        rawlog = os.path.join(out_dir, "sim.rawlog")
        run(tool, "add-odometry", stamped, rawlog, gt, "1")
        run(tool, "to-observations", rawlog, os.path.join(out_dir, "sim_obs.rawlog"))
    print("wrote %s, %s and sim_obs.rawlog (%d scans), %s" % (map_png, rawlog, len(stamps), gt))
    make_map_file(offline, out_dir)
    make_moved_box_map(offline, out_dir)


if __name__ == "__main__":
    main()
