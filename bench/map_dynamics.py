#!/usr/bin/python3
"""Benchmark: does the map follow the world across days (issue 51)?

Per run (seed printed, fresh each run unless --seeds is given):
  1. Draws a day-1 world (24 m x 14 m, 0.05 m/px): a hall with fixed pillars, room A behind a
     door, and, placed at random in the hall's middle band, a pillar (removed on day 2), a 0.2 x
     1.5 m wall stub (moved 3 m along x on day 2); on day 2 a 1 x 1 m box is added and room A's
     door is closed (room A is not seen on day 2).
  2. Simulates day 1 (a loop of the hall and a visit of room A) and three day-2 passes (the hall
     loop, each its own rawlog) with evidential_slam_simulate.
  3. Maps day 1 with evidential_slam_offline, then continues the saved map pass by pass
     (--load-map: the lifelong workflow), for every --flip-scans value (0 = unbounded cells).
  4. The probabilistic peer: OctoMap's log-odds tree with its clamping (0.12 / 0.97), fed the
     same scans at the poses our SLAM estimated (evidential_slam_logodds_baseline), continued the
     same way.
Scores after each day-2 pass (the maps in the SLAM's frame, the world's cells moved into it by
the best rigid fit of the run's trajectory to its ground truth):
  added    share of the hit cells of the box, the stub's new place and the closed door (object
           cells with a free neighbour that a day-2 pose sees within 20 m) occupied
           (BetP > 0.5 / p > 0.5) in their 3 x 3 neighbourhood (1 cell of pose error allowed);
  removed  share of the cells occupied on day 1's map within 0.1 m of the pillar and the stub's
           old place that are free (BetP < 0.5 / p < 0.5);
  kept     share of the cells occupied on day 1's map inside room A (not seen on day 2) still
           occupied;
  ATE      of each run (summary.json).
Also the median anomaly (bits, anomaly layer) over the added and removed cells after pass 1.

--within-run: changes inside one run instead (the same hall, pillar and stub fixed). A lap with
room A's door open and a 1.0 x 0.8 m cart parked in the middle band; at the lap's end (the time
from simulating the first lap alone) the door closes, a 1.0 x 0.8 m box appears on floor the lap
saw free and the cart goes (bar objects of evidential_slam_simulate --objects); then --passes more
laps, all one rawlog. Our SLAM runs on it stopped at the end of lap 1, 2, 3 after the change
(--max-scans: the map /map shows at that moment), the log-odds peer on the scans and poses of each.
Scores: the door's and the box's hit cells (seen from the route after the change) occupied within
one cell, the cart's hit cells (seen before) free, and the ATE of the whole run. --check turns it
into the CI smoke test.
Standard library only: /usr/bin/python3 bench/map_dynamics.py --help
"""

import argparse
import json
import math
import os
import random
import re
import statistics
import struct
import subprocess
import sys
import zlib
from array import array

import smoke_check  # bench/, this script's folder

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
BIN = os.path.join(REPO, ".ws", "devel", "lib", "evidential_slam")
RES = 0.05
W_M, H_M = 24.0, 14.0
HALL_LOOP = [(4, 6), (21, 6), (21, 12), (2, 12), (2, 6), (4, 6)]
ROOM_A_VISIT = [(3.5, 6), (3.5, 2.5), (8.5, 2.5), (3.5, 2.5), (3.5, 6), (4, 6)]


def px(m):
    return int(round(m / RES))


class World:
    """Occupancy image, True = obstacle; row 0 = lowest y."""

    def __init__(self):
        self.w, self.h = px(W_M), px(H_M)
        self.occ = [[False] * self.w for _ in range(self.h)]

    def box(self, x0, y0, x1, y1, value=True):
        for y in range(px(y0), px(y1)):
            for x in range(px(x0), px(x1)):
                self.occ[y][x] = value

    def copy(self):
        c = World()
        c.occ = [row[:] for row in self.occ]
        return c

    def at(self, cx, cy):
        return 0 <= cx < self.w and 0 <= cy < self.h and self.occ[cy][cx]

    def write_png(self, path):
        write_png(path, self.w, self.h, [bytes(0 if v else 255 for v in row)
                                         for row in reversed(self.occ)], 0)


def write_png(path, w, h, rows, color_type):
    """8-bit PNG from `rows` (top row first): color_type 0 = grey, 2 = RGB."""
    raw = b"".join(b"\x00" + bytes(row) for row in rows)

    def chunk(kind, data):
        c = struct.pack(">I", len(data)) + kind + data
        return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, color_type, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def make_base():
    """The hall, room A (door open) and the fixed furniture and pillars."""
    base = World()
    t = 0.2
    base.box(0, 0, W_M, t)
    base.box(0, H_M - t, W_M, H_M)
    base.box(0, 0, t, H_M)
    base.box(W_M - t, 0, W_M, H_M)
    base.box(t, 4.0, 3.0, 4.2)  # room A's wall to the hall, door at x 3..4
    base.box(4.0, 4.0, 10.0, 4.2)
    base.box(10.0, t, 10.2, 4.2)  # room A's east wall; the rest of the south strip is solid
    base.box(10.2, t, W_M - t, 4.2)
    base.box(5.5, 1.2, 6.5, 1.6)  # furniture in room A
    base.box(8.0, 3.3, 9.2, 3.7)
    base.box(1.0, 0.8, 1.4, 1.8)
    for x in (7.0, 12.0, 17.0):  # fixed pillars along the hall's walls
        base.box(x, 4.2, x + 0.4, 4.6)
        base.box(x + 2.0, H_M - t - 0.4, x + 2.4, H_M - t)
    return base


def make_worlds(rng):
    """Day-1 and day-2 worlds and the changed objects' cell sets (world cells)."""
    base = make_base()
    # The changed objects, in the middle band y 7.4 .. 10.6 (the route runs at y 6 and 12), apart.
    slots = rng.sample([5.0, 8.5, 12.0, 15.5, 19.0], 3)
    pillar_x, box_x, stub_x = slots
    pillar = (pillar_x, rng.uniform(7.6, 10.0), 0.5, 0.5)
    box = (box_x, rng.uniform(7.6, 9.6), 1.0, 1.0)
    stub_dx = 3.0 if stub_x < 12.0 else -3.0
    stub_y = rng.uniform(7.6, 8.9)
    stub_old = (stub_x, stub_y, 0.2, 1.5)
    stub_new = (stub_x + stub_dx, stub_y, 0.2, 1.5)
    if abs(stub_new[0] - pillar[0]) < 1.5 or abs(stub_new[0] - box[0]) < 1.5:
        stub_new = (stub_x + stub_dx, 10.6 - 1.5 - 0.05, 0.2, 1.5) if stub_y < 8.5 else \
            (stub_x + stub_dx, 7.5, 0.2, 1.5)
    door = (3.0, 4.0, 1.0, 0.2)

    def rect(r):
        return (r[0], r[1], r[0] + r[2], r[1] + r[3])

    day1, day2 = base.copy(), base.copy()
    day1.box(*rect(pillar))
    day1.box(*rect(stub_old))
    day2.box(*rect(box))
    day2.box(*rect(stub_new))
    day2.box(*rect(door))
    objects = {"pillar": rect(pillar), "stub_old": rect(stub_old), "box": rect(box),
               "stub_new": rect(stub_new), "door": rect(door)}
    return day1, day2, objects


def write_waypoints(path, points):
    with open(path, "w") as f:
        for x, y in points:
            f.write(f"{x} {y}\n")


def run(cmd, log):
    with open(log, "w") as f:
        r = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT)
    if r.returncode != 0:
        sys.exit(f"failed ({r.returncode}): {' '.join(cmd)}\n  see {log}")


def read_gt(path):
    poses = []
    with open(path) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                t, x, y, a = map(float, line.split()[:4])
                poses.append((t, x, y, a))
    return poses


def read_npy(path):
    with open(path, "rb") as f:
        data = f.read()
    hlen = struct.unpack("<H", data[8:10])[0]
    header = data[10:10 + hlen].decode("latin1")
    shape = tuple(int(v) for v in re.search(r"\((\d+), (\d+)\)", header).groups())
    kind = re.search(r"'descr': '([^']+)'", header).group(1)
    a = array("f" if kind == "<f4" else "B")
    a.frombytes(data[10 + hlen:])
    return shape, a


class EvMap:
    """A saved map's layers (layers/*.npy, map.yaml)."""

    def __init__(self, out_dir):
        d = os.path.join(out_dir, "layers")
        meta = open(os.path.join(d, "map.yaml")).read()
        o = re.search(r"origin: \[([-\d.e]+), ([-\d.e]+)", meta)
        self.x0, self.y0 = float(o.group(1)), float(o.group(2))
        self.res = float(re.search(r"resolution: ([\d.]+)", meta).group(1))
        (self.h, self.w), self.betp = read_npy(os.path.join(d, "pignistic.npy"))
        _, self.anomaly = read_npy(os.path.join(d, "anomaly.npy"))

    def value(self, layer, x, y):
        c, r = int(math.floor((x - self.x0) / self.res)), int(math.floor((y - self.y0) / self.res))
        if not (0 <= c < self.w and 0 <= r < self.h):
            return None
        return layer[r * self.w + c]

    def p(self, x, y):
        v = self.value(self.betp, x, y)
        return 0.5 if v is None else v


class LogOddsMap:
    """The baseline's grid file: p(occupied) per cell, -1 unknown."""

    def __init__(self, path):
        with open(path) as f:
            x0, y0, res, w, h = f.readline().split()
            self.x0, self.y0, self.res, self.w, self.h = float(x0), float(y0), float(res), int(w), int(h)
            self.cells = [list(map(int, line.split())) for line in f]

    def p(self, x, y):
        c, r = int(math.floor((x - self.x0) / self.res)), int(math.floor((y - self.y0) / self.res))
        if not (0 <= c < self.w and 0 <= r < self.h) or self.cells[r][c] < 0:
            return 0.5
        return self.cells[r][c] / 100.0


def visible_surface(world, rect, poses, max_range=20.0):
    """World cells of the object `rect` with a free 4-neighbour that one of `poses` (GT, robot
    frame ~ laser, 180 deg ahead) sees unobstructed within max_range."""
    x0, y0, x1, y1 = (px(v) for v in rect)
    return visible_cells(world, [(cx, cy) for cy in range(y0, y1) for cx in range(x0, x1)], poses,
                         max_range)


def visible_cells(world, footprint, poses, max_range=20.0):
    """The cells of `footprint` (world cells, obstacles in `world`) with a free 4-neighbour that
    one of `poses` sees unobstructed within max_range."""
    cells = []
    for cx, cy in footprint:
        if any(not world.at(cx + dx, cy + dy) for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1))):
            cells.append((cx, cy))
    seen = []
    for cx, cy in cells:
        tx, ty = (cx + 0.5) * RES, (cy + 0.5) * RES
        for _, x, y, a in poses:
            dx, dy = tx - x, ty - y
            d = math.hypot(dx, dy)
            if d > max_range or math.cos(math.atan2(dy, dx) - a) < 0.0:
                continue
            steps = int(d / (RES * 0.5))
            ok = True
            for i in range(1, steps):
                sx, sy = int((x + dx * i / steps) / RES), int((y + dy * i / steps) / RES)
                if (sx, sy) == (cx, cy):
                    break
                if world.at(sx, sy):
                    ok = False
                    break
            if ok:
                seen.append((cx, cy))
                break
    return seen


def read_tum(path):
    poses = []
    with open(path) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                v = line.split()
                poses.append((float(v[0]), float(v[1]), float(v[2])))
    return poses


class Alignment:
    """The rigid 2-D transform taking world points into a SLAM run's map frame: the best fit
    (Kabsch, as the ATE's alignment) of the run's trajectory.tum to its ground truth, so the
    map's own frame error (a slowly turned heading shifts far cells) is not scored as change."""

    def __init__(self, tum_path, gt):
        est = read_tum(tum_path)
        gt_by_t = {round(t, 3): (x, y) for t, x, y, _ in gt}
        pairs = [((x, y), gt_by_t[round(t, 3)]) for t, x, y in est if round(t, 3) in gt_by_t]
        n = len(pairs)
        mw = [sum(p[1][i] for p in pairs) / n for i in (0, 1)]
        ms = [sum(p[0][i] for p in pairs) / n for i in (0, 1)]
        sxx = sxy = 0.0
        for (ex, ey), (wx, wy) in pairs:
            ax, ay, bx, by = wx - mw[0], wy - mw[1], ex - ms[0], ey - ms[1]
            sxx += ax * bx + ay * by
            sxy += ax * by - ay * bx
        self.angle = math.atan2(sxy, sxx)  # world -> slam rotation
        c, s = math.cos(self.angle), math.sin(self.angle)
        self.c, self.s = c, s
        self.tx = ms[0] - (c * mw[0] - s * mw[1])
        self.ty = ms[1] - (s * mw[0] + c * mw[1])

    def __call__(self, x, y):
        return self.c * x - self.s * y + self.tx, self.s * x + self.c * y + self.ty


def write_figure(path, maps, aligns, added_world, removed_cells, last):
    """Day 1's map, day 2's after pass `last`, side by side (BetP, dark = occupied), 2 px apart;
    on both, the cells scored as added (red) and removed (blue) at their place in each map: full
    colour where that map holds them occupied, pale where free."""
    x0 = min(m.x0 for m in (maps[0], maps[last]))
    y0 = min(m.y0 for m in (maps[0], maps[last]))
    x1 = max(m.x0 + m.w * m.res for m in (maps[0], maps[last]))
    y1 = max(m.y0 + m.h * m.res for m in (maps[0], maps[last]))
    w, h = int((x1 - x0) / RES), int((y1 - y0) / RES)
    panels = []
    for k in (0, last):
        mp = maps[k]
        img = [[(int(255 * (1 - mp.p(x0 + (c + 0.5) * RES, y0 + (r + 0.5) * RES))),) * 3
                for c in range(w)] for r in range(h)]
        marks = [(aligns[k](*q), (220, 30, 30)) for q in added_world]
        # removed_cells are in day 1's map frame: into day 2's through the world frame.
        for q in removed_cells:
            if k == 0:
                marks.append((q, (30, 80, 230)))
            else:
                a0, ak = aligns[0], aligns[k]
                dx, dy = q[0] - a0.tx, q[1] - a0.ty
                wx, wy = a0.c * dx + a0.s * dy, -a0.s * dx + a0.c * dy
                marks.append((ak(wx, wy), (30, 80, 230)))
        for (qx, qy), rgb in marks:
            c, r = int((qx - x0) / RES), int((qy - y0) / RES)
            if 0 <= c < w and 0 <= r < h:
                # Full colour where the map holds the cell occupied, a pale tint where free.
                a = 1.0 if mp.p(qx, qy) > 0.5 else 0.3
                img[r][c] = tuple(int(a * v + (1 - a) * 255) for v in rgb)
        panels.append(img)
    rows = []
    for r in reversed(range(h)):
        row = []
        for img in panels:
            for v in img[r]:
                row.extend(v)
            row.extend((255, 255, 255) * 2)
        rows.append(row[:-6])
    write_png(path, 2 * w + 2, h, rows, 2)


def capsule_cells(a, b, r):
    """World cells whose centre lies within r of segment a-b (a `bar` object's footprint)."""
    cells = []
    for cy in range(px(min(a[1], b[1]) - r) - 1, px(max(a[1], b[1]) + r) + 1):
        for cx in range(px(min(a[0], b[0]) - r) - 1, px(max(a[0], b[0]) + r) + 1):
            x, y = (cx + 0.5) * RES, (cy + 0.5) * RES
            dx, dy = b[0] - a[0], b[1] - a[1]
            u = max(0.0, min(1.0, ((x - a[0]) * dx + (y - a[1]) * dy) / max(1e-12, dx * dx + dy * dy)))
            if math.hypot(x - a[0] - u * dx, y - a[1] - u * dy) <= r:
                cells.append((cx, cy))
    return cells


def pass_ends(gt, start=(4.0, 6.0)):
    """Indices of the scans at which the robot is back at `start` after a lap of the hall."""
    ends, away = [], False
    for i, (_, x, y, _) in enumerate(gt):
        d = math.hypot(x - start[0], y - start[1])
        if d > 3.0:
            away = True
        elif d < 0.2 and away:
            ends.append(i)
            away = False
    return ends


def within_run(args, seed, methods, rows):
    """One run of the hall with changes half-way (issue 51's within-run case): a lap with room
    A's door open and a cart parked in the hall, then at the lap's end the door closes, a box is
    placed in hall floor the first lap saw free and the cart is taken away; `passes` more laps.
    Each map is scored as /map shows it at the end of lap 1, 2, 3 after the change."""
    rng = random.Random(seed)
    work = os.path.join(args.work, f"within_{seed}")
    os.makedirs(work, exist_ok=True)
    sim = os.path.join(args.bin, "evidential_slam_simulate")
    offline = os.path.join(args.bin, "evidential_slam_offline")
    baseline = os.path.join(args.bin, "evidential_slam_logodds_baseline")
    base = make_base()
    pillar_x, stub_x, box_x, cart_x = rng.sample([5.0, 8.5, 12.0, 15.5, 19.0], 4)
    py, sy = rng.uniform(7.6, 10.0), rng.uniform(7.6, 8.9)
    base.box(pillar_x, py, pillar_x + 0.5, py + 0.5)  # fixed in this run
    base.box(stub_x, sy, stub_x + 0.2, sy + 1.5)
    # A 1.0 x 0.8 m box and cart: capsules round a 0.2 m segment, radius 0.4.
    box_c = (box_x + 0.5, rng.uniform(8.0, 10.2))
    cart_c = (cart_x + 0.5, rng.uniform(8.0, 10.2))
    box = ((box_c[0] - 0.1, box_c[1]), (box_c[0] + 0.1, box_c[1]), 0.4)
    cart = ((cart_c[0] - 0.1, cart_c[1]), (cart_c[0] + 0.1, cart_c[1]), 0.4)
    door = ((3.0, 4.1), (4.0, 4.1), 0.1)
    base.write_png(os.path.join(work, "world.png"))
    write_waypoints(os.path.join(work, "lap.txt"), HALL_LOOP)
    write_waypoints(os.path.join(work, "route.txt"), HALL_LOOP + HALL_LOOP[1:] * args.passes)
    sim_cmd = [sim, "--map", os.path.join(work, "world.png"), "--resolution", str(RES),
               "--origin-x", "0", "--origin-y", "0", "--seed", str(seed * 10)]
    # The first lap alone gives the time of the change: its end (the truth does not depend on
    # the noise or the objects).
    lap = os.path.join(work, "lap.rawlog")
    run(sim_cmd + ["--waypoints", os.path.join(work, "lap.txt"), "--out", lap], lap + ".txt")
    t_change = read_gt(lap + ".GT.txt")[-1][0]
    with open(os.path.join(work, "objects.txt"), "w") as f:
        for (a, b, r), t0, t1, kind in ((door, t_change, 1e6, "door closes"),
                                        (box, t_change, 1e6, "box placed"),
                                        (cart, 0.0, t_change, "cart removed")):
            f.write("bar %.3f %.3f %.3f %.3f %.3f %.3f %.3f  # %s\n" % (t0, t1, *a, *b, r, kind))
    rawlog = os.path.join(work, "run.rawlog")
    run(sim_cmd + ["--waypoints", os.path.join(work, "route.txt"), "--objects",
                   os.path.join(work, "objects.txt"), "--out", rawlog], rawlog + ".txt")
    gt = read_gt(rawlog + ".GT.txt")
    ends = pass_ends(gt)
    if len(ends) != args.passes + 1:
        sys.exit(f"seed {seed}: found {len(ends)} laps in {rawlog}.GT.txt, expected {args.passes + 1}")

    def changed(obj):
        return [c for c in capsule_cells(*obj) if not base.at(*c)]

    after, before = base.copy(), base.copy()
    for obj in (door, box):
        for cx, cy in changed(obj):
            after.occ[cy][cx] = True
    for cx, cy in changed(cart):
        before.occ[cy][cx] = True
    gt_after = [p for p in gt if p[0] > t_change][::40]
    gt_before = [p for p in gt if p[0] <= t_change][::40]
    targets = {"door": visible_cells(after, changed(door), gt_after),
               "box": visible_cells(after, changed(box), gt_after),
               "cart": visible_cells(before, changed(cart), gt_before)}
    first = methods[0].replace(" ", "_").replace("=", "")
    for m in methods:
        tag = m.replace(" ", "_").replace("=", "")
        row = {"seed": seed, **{f"{k}_n": len(v) for k, v in targets.items()}}
        for k in range(1, args.passes + 1):
            out = os.path.join(work, f"{tag}.pass{k}")
            src = os.path.join(work, f"{first}.pass{k}")
            if m == "log-odds":
                run([baseline, "--rawlog", rawlog, "--trajectory", os.path.join(src, "trajectory.tum"),
                     "--stamps", os.path.join(src, "conflict.csv"), "--grid-out", out + ".grid.txt",
                     "--window", "-5,-7,21,9"], out + ".log")
                mp = LogOddsMap(out + ".grid.txt")
            else:
                n = int(m.split("=")[1]) if "=" in m else 0
                run(["nice", "-n", "10", offline, "--rawlog", rawlog, "--ground-truth",
                     rawlog + ".GT.txt", "--out", out, "--particles", str(args.particles),
                     "--threads", "1", "--seed", str(seed), "--quiet", "--max-scans",
                     str(ends[k] + 1), "--param", f"flip_scans={n}"], out + ".log")
                mp = EvMap(out)
                src = out
            align = Alignment(os.path.join(src, "trajectory.tum"), gt)

            def occ3(q):
                return max(mp.p(q[0] + dx * RES, q[1] + dy * RES)
                           for dx in (-1, 0, 1) for dy in (-1, 0, 1)) > 0.5

            for name, cells in targets.items():
                qs = [align((cx + 0.5) * RES, (cy + 0.5) * RES) for cx, cy in cells]
                hit = [mp.p(*q) < 0.5 for q in qs] if name == "cart" else [occ3(q) for q in qs]
                row[f"{name}{k}"] = sum(hit) / max(1, len(hit))
            if m != "log-odds" and k == args.passes:
                row["ate"] = json.load(open(os.path.join(out, "summary.json")))["ate_rmse_m"]
        rows[m].append(row)
        print(f"seed {seed} within-run {m}: " + json.dumps(row), flush=True)


def print_within(args, seeds, methods, rows):
    laps = " / ".join(str(k) for k in range(1, args.passes + 1))
    print(f"\n| method | door closed: occupied after lap {laps} | box placed: occupied after "
          f"{laps} | cart removed: free after {laps} | ATE (m) |")
    print("|---|---|---|---|---|")
    for m in methods:
        rs = rows[m]

        def pcts(name):
            return " / ".join("%.1f" % (100 * statistics.mean(r[f"{name}{k}"] for r in rs))
                              for k in range(1, args.passes + 1)) + " %"

        ate = "%.3f" % statistics.mean(r["ate"] for r in rs) if "ate" in rs[0] else "(our poses)"
        print(f"| {m} | {pcts('door')} | {pcts('box')} | {pcts('cart')} | {ate} |")
    n = {k: sum(r[f"{k}_n"] for r in rows[methods[0]]) for k in ("door", "box", "cart")}
    print(f"\nmeans over {len(seeds)} generated runs, seeds {' '.join(map(str, seeds))}; cells: "
          f"door {n['door']}, box {n['box']}, cart {n['cart']} (hit cells; occupied within one "
          "cell, free at the cell)")


def check_within(args, methods, rows):
    """The smoke test's verdict (--check): bounded cells let every within-run change through."""
    failures = []
    k = args.passes
    for m in methods:
        if not m.startswith("ours N="):
            continue
        for r in rows[m]:
            for name, floor in (("door", 0.8), ("box", 0.8), ("cart", 0.9)):
                if r[f"{name}{k}"] < floor:
                    failures.append(f"seed {r['seed']} {m}: {name} {100 * r[f'{name}{k}']:.1f} % "
                                    f"after lap {k} (< {100 * floor:.0f} %)")
    return smoke_check.report(failures, args.junit, "map_dynamics_within", "within_run")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=2, help="generated day-1/day-2 pairs [2]")
    ap.add_argument("--seeds", type=int, nargs="*", help="world/simulation seeds (default: fresh)")
    ap.add_argument("--flip-scans", type=int, nargs="+", default=[9, 0],
                    help="flip_scans values for our SLAM; 0 = unbounded cells [9 0]")
    ap.add_argument("--particles", type=int, default=30)
    ap.add_argument("--passes", type=int, default=3)
    ap.add_argument("--work", default="/tmp/map_dynamics", help="work directory")
    ap.add_argument("--bin", default=BIN, help="directory of the built programs")
    ap.add_argument("--figure", help="PNG: the first run's day 1 and last day-2 pass side by side "
                    "(first method), added cells red, removed blue; full colour = occupied on that map")
    ap.add_argument("--check", action="store_true",
                    help="with --within-run: exit 1 unless, for every bounded method (N > 0), after "
                    "the last lap >= 80 %% of the door's and the box's cells are occupied and >= 90 %% "
                    "of the cart's free (the CI smoke test)")
    ap.add_argument("--junit", help="with --check: write the verdict as a JUnit file")
    ap.add_argument("--within-run", action="store_true",
                    help="the within-run changes instead of the day pairs: one run per seed, a lap, "
                    "then a door closes, a box is placed, a cart is removed, then --passes laps")
    args = ap.parse_args()
    seeds = args.seeds or [random.SystemRandom().randrange(1, 10**6) for _ in range(args.runs)]
    print(f"seeds: {' '.join(map(str, seeds))}  (rerun: --seeds {' '.join(map(str, seeds))})")
    if args.within_run:
        methods = [f"ours N={n}" if n else "ours unbounded" for n in args.flip_scans] + ["log-odds"]
        rows = {m: [] for m in methods}
        for seed in seeds:
            within_run(args, seed, methods, rows)
        print_within(args, seeds, methods, rows)
        if args.check and not check_within(args, methods, rows):
            sys.exit(1)
        return
    sim = os.path.join(args.bin, "evidential_slam_simulate")
    offline = os.path.join(args.bin, "evidential_slam_offline")
    baseline = os.path.join(args.bin, "evidential_slam_logodds_baseline")
    methods = [f"ours N={n}" if n else "ours unbounded" for n in args.flip_scans] + ["log-odds"]
    rows = {m: [] for m in methods}
    for seed in seeds:
        rng = random.Random(seed)
        work = os.path.join(args.work, str(seed))
        os.makedirs(work, exist_ok=True)
        day1, day2, objects = make_worlds(rng)
        day1.write_png(os.path.join(work, "day1.png"))
        day2.write_png(os.path.join(work, "day2.png"))
        write_waypoints(os.path.join(work, "day1.txt"), HALL_LOOP + ROOM_A_VISIT[1:])
        write_waypoints(os.path.join(work, "day2.txt"), HALL_LOOP)
        logs = []
        for day, k in [(1, 0)] + [(2, k) for k in range(1, args.passes + 1)]:
            name = "day1" if day == 1 else f"day2_pass{k}"
            rawlog = os.path.join(work, name + ".rawlog")
            run([sim, "--map", os.path.join(work, f"day{day}.png"), "--resolution", str(RES),
                 "--origin-x", "0", "--origin-y", "0", "--waypoints",
                 os.path.join(work, f"day{day}.txt"), "--seed", str(seed * 10 + k),
                 "--out", rawlog], os.path.join(work, name + ".sim.txt"))
            logs.append((name, rawlog))
        gts = [read_gt(rawlog + ".GT.txt") for _, rawlog in logs]
        gt2 = [p for i, p in enumerate(gts[1]) if i % 40 == 0]
        added = {n: visible_surface(day2, objects[n], gt2) for n in ("box", "stub_new", "door")}
        for m in methods:
            outs = []
            prev = None
            for name, rawlog in logs:
                tag = m.replace(" ", "_").replace("=", "")
                out = os.path.join(work, f"{tag}.{name}")
                if m == "log-odds":
                    src = os.path.join(work, f"{methods[0].replace(' ', '_').replace('=', '')}.{name}")
                    cmd = [baseline, "--rawlog", rawlog, "--trajectory",
                           os.path.join(src, "trajectory.tum"), "--stamps",
                           os.path.join(src, "conflict.csv"), "--grid-out", out + ".grid.txt",
                           "--window", "-5,-7,21,9", "--save-tree", out + ".ot"]
                    if prev:
                        cmd += ["--load-tree", prev + ".ot"]
                    run(cmd, out + ".log")
                else:
                    n = int(m.split("=")[1]) if "=" in m else 0
                    cmd = ["nice", "-n", "10", offline, "--rawlog", rawlog, "--ground-truth",
                           rawlog + ".GT.txt", "--out", out, "--particles", str(args.particles),
                           "--threads", "1", "--seed", str(seed), "--quiet", "--param",
                           f"flip_scans={n}"]
                    if prev:
                        cmd += ["--load-map", prev]
                    run(cmd, out + ".log")
                prev = out
                outs.append(out)
            load = (lambda o: LogOddsMap(o + ".grid.txt")) if m == "log-odds" else EvMap
            maps = [load(o) for o in outs]
            # World -> map frame of each run, from our trajectories (the peer's are ours too).
            src = outs if m != "log-odds" else [
                os.path.join(work, f"{methods[0].replace(' ', '_').replace('=', '')}.{name}")
                for name, _ in logs]
            aligns = [Alignment(os.path.join(o, "trajectory.tum"), gt) for o, gt in zip(src, gts)]
            d1 = maps[0]
            removed_cells, kept_cells = [], []
            for r in (objects["pillar"], objects["stub_old"]):
                for cy in range(px(r[1] - 0.1), px(r[3] + 0.1)):
                    for cx in range(px(r[0] - 0.1), px(r[2] + 0.1)):
                        q = aligns[0]((cx + 0.5) * RES, (cy + 0.5) * RES)
                        if d1.p(*q) > 0.5:
                            removed_cells.append(q)
            for cy in range(px(0.2), px(3.95)):
                for cx in range(px(0.2), px(10.0)):
                    q = aligns[0]((cx + 0.5) * RES, (cy + 0.5) * RES)
                    if d1.p(*q) > 0.5:
                        kept_cells.append(q)
            added_world = [((cx + 0.5) * RES, (cy + 0.5) * RES)
                           for cells in added.values() for cx, cy in cells]

            def occ3(mp, q):
                return max(mp.p(q[0] + dx * RES, q[1] + dy * RES)
                           for dx in (-1, 0, 1) for dy in (-1, 0, 1)) > 0.5

            row = {"seed": seed, "added_n": len(added_world), "removed_n": len(removed_cells),
                   "kept_n": len(kept_cells)}
            for k, mp in enumerate(maps[1:], 1):
                added_cells = [aligns[k](*w) for w in added_world]
                row[f"added{k}"] = sum(occ3(mp, q) for q in added_cells) / max(1, len(added_cells))
                row[f"removed{k}"] = sum(mp.p(*q) < 0.5 for q in removed_cells) / max(1, len(removed_cells))
                row[f"kept{k}"] = sum(mp.p(*q) > 0.5 for q in kept_cells) / max(1, len(kept_cells))
            if m != "log-odds":
                row["ate"] = [json.load(open(os.path.join(o, "summary.json")))["ate_rmse_m"]
                              for o in outs]
                p1 = maps[1]
                an = [p1.value(p1.anomaly, *aligns[1](*w)) or 0.0 for w in added_world]
                ar = [p1.value(p1.anomaly, *q) or 0.0 for q in removed_cells]
                row["anomaly_added"] = statistics.median(an) if an else 0.0
                row["anomaly_removed"] = statistics.median(ar) if ar else 0.0
            rows[m].append(row)
            print(f"seed {seed} {m}: " + json.dumps(row), flush=True)
            if args.figure and m == methods[0] and seed == seeds[0]:
                write_figure(args.figure, maps, aligns, added_world, removed_cells, args.passes)
                print(f"figure: {args.figure}")

    print("\n| method | added occupied after pass 1 / 2 / 3 | removed free after 1 / 2 / 3 | "
          "unseen walls kept | ATE day 1 | ATE day 2 (passes) | anomaly added / removed |")
    print("|---|---|---|---|---|---|---|")
    for m in methods:
        rs = rows[m]
        if not rs:
            continue

        def pct(key):
            return "%.1f %%" % (100 * statistics.mean(r[key] for r in rs))

        added = " / ".join(pct(f"added{k}") for k in range(1, args.passes + 1))
        removed = " / ".join(pct(f"removed{k}") for k in range(1, args.passes + 1))
        kept = pct(f"kept{args.passes}")
        if "ate" in rs[0]:
            ate1 = "%.3f m" % statistics.mean(r["ate"][0] for r in rs)
            ate2 = " / ".join("%.3f" % statistics.mean(r["ate"][k] for r in rs)
                              for k in range(1, args.passes + 1)) + " m"
            anomaly = "%.1f / %.1f" % (statistics.mean(r["anomaly_added"] for r in rs),
                                       statistics.mean(r["anomaly_removed"] for r in rs))
        else:
            ate1 = ate2 = anomaly = "(our poses)"
        print(f"| {m} | {added} | {removed} | {kept} | {ate1} | {ate2} | {anomaly} |")
    print(f"\nmeans over {len(seeds)} generated pairs, seeds {' '.join(map(str, seeds))}; "
          f"cells: added {sum(r['added_n'] for r in rows[methods[0]])}, removed (ours N="
          f"{args.flip_scans[0]}, day 1) {sum(r['removed_n'] for r in rows[methods[0]])}, "
          f"unseen walls {sum(r['kept_n'] for r in rows[methods[0]])}")


if __name__ == "__main__":
    smoke_check.run(main, "map_dynamics_within", "within_run")
