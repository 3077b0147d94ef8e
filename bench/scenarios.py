"""Scenario generator of the change-detection benchmark (bench/change_detection.py, issue 52).

A scenario is a world, a route and what happens on it, all drawn from one seed:
  worlds   office    a corridor with rooms on both sides behind 1 m doors, furniture in the rooms;
           corridor  a long corridor with recesses and two side rooms;
           loop      a hall round a central block, with pillars;
  route    out along the corridor (visiting a room or two) and back, or two laps of the loop: the
           way back / the second lap runs through space the map already knows;
  kind     clean     nothing happens;
           kidnap    at a random time on the way back the true pose jumps 0.3-3 m and turns 0-90
                     degrees (landing in free space with a clear line to the next waypoint);
           objects   people crossing ahead of the robot, a box parked then removed, a door that
                     opens or closes (bar/disc objects of evidential_slam_simulate --objects).
Ground truth: the world image, the events (their times and places) and the simulator's
--truth-scans file (true poses, ranges and which object each ray ended on).
"""

import math
import struct
import zlib

import numpy as np

RES = 0.05
WALL = 0.2


def px(m):
    return int(round(m / RES))


class World:
    """Occupancy (True = wall), row 0 = lowest y, the image's lower-left corner at (0, 0)."""

    def __init__(self, w_m, h_m, solid=False):
        self.w_m, self.h_m = w_m, h_m
        self.occ = np.full((px(h_m), px(w_m)), solid, dtype=bool)
        self.doors = []  # (x0, y0, x1, y1): doorways the route does not use (a door may close them)
        self._clear = None

    def box(self, x0, y0, x1, y1, value=True):
        self.occ[max(0, px(y0)):max(0, px(y1)), max(0, px(x0)):max(0, px(x1))] = value
        self._clear = None

    def border(self):
        self.box(0, 0, self.w_m, WALL)
        self.box(0, self.h_m - WALL, self.w_m, self.h_m)
        self.box(0, 0, WALL, self.h_m)
        self.box(self.w_m - WALL, 0, self.w_m, self.h_m)

    def clearance(self, x, y):
        """Distance (m) from (x, y) to the nearest wall cell, up to 2 m."""
        c, r = int(x / RES), int(y / RES)
        if not (0 <= c < self.occ.shape[1] and 0 <= r < self.occ.shape[0]) or self.occ[r, c]:
            return 0.0
        k = px(2.0)
        r0, r1, c0, c1 = max(0, r - k), min(self.occ.shape[0], r + k + 1), max(0, c - k), \
            min(self.occ.shape[1], c + k + 1)
        rr, cc = np.nonzero(self.occ[r0:r1, c0:c1])
        if len(rr) == 0:
            return 2.0
        d = np.hypot((rr + r0 + 0.5) * RES - y, (cc + c0 + 0.5) * RES - x)
        return float(min(2.0, d.min()))

    def segment_clear(self, a, b, margin):
        n = max(2, int(math.hypot(b[0] - a[0], b[1] - a[1]) / 0.05))
        return all(self.clearance(a[0] + (b[0] - a[0]) * i / n, a[1] + (b[1] - a[1]) * i / n)
                   >= margin for i in range(n + 1))

    def write_png(self, path):
        raw = b"".join(b"\x00" + bytes(np.where(row, 0, 255).astype(np.uint8))
                       for row in self.occ[::-1])

        def chunk(kind, data):
            c = struct.pack(">I", len(data)) + kind + data
            return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

        h, w = self.occ.shape
        with open(path, "wb") as f:
            f.write(b"\x89PNG\r\n\x1a\n")
            f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0)))
            f.write(chunk(b"IDAT", zlib.compress(raw, 6)))
            f.write(chunk(b"IEND", b""))


def room_visit(door_x, y_corridor, y_door, y_room):
    """Waypoints from the corridor's centre line into a room through its door and back."""
    return [(door_x, y_corridor), (door_x, y_door), (door_x, y_room), (door_x, y_door),
            (door_x, y_corridor)]


def office(rng):
    length = rng.uniform(16, 24)
    cw = rng.uniform(1.8, 2.6)
    depth = rng.uniform(3.0, 4.5)
    h = 2 * depth + cw + 3 * WALL
    world = World(length, h)
    world.border()
    y_lo = WALL + depth  # south rooms' wall to the corridor
    y_hi = y_lo + WALL + cw  # north rooms' wall to the corridor
    yc = y_lo + WALL + cw / 2
    visits = []
    for south in (True, False):
        wy0, wy1 = (y_lo, y_lo + WALL) if south else (y_hi, y_hi + WALL)
        world.box(0, wy0, length, wy1)
        x = WALL
        rooms = []
        while length - WALL - x > 2.5:
            w = min(rng.uniform(3.0, 5.0), length - WALL - x)
            if length - WALL - (x + w) < 2.5:
                w = length - WALL - x
            rooms.append((x, x + w))
            x += w
            if x < length - WALL - 0.1:
                world.box(x, WALL if south else y_hi + WALL, x + WALL, y_lo if south else h - WALL)
                x += WALL
        for x0, x1 in rooms:
            dx = rng.uniform(x0 + 0.4, x1 - 1.4)
            world.box(dx, wy0, dx + 1.0, wy1, False)
            ry0, ry1 = (WALL, y_lo) if south else (y_hi + WALL, h - WALL)
            # Furniture against the far wall, away from the door's line.
            fw, fd = rng.uniform(0.6, 1.4), rng.uniform(0.4, 0.8)
            fx = rng.uniform(x0 + 0.3, x1 - 0.3 - fw)
            if abs((fx + fw / 2) - (dx + 0.5)) > fw / 2 + 0.9:
                fy0 = ry0 + 0.3 if south else ry1 - 0.3 - fd
                world.box(fx, fy0, fx + fw, fy0 + fd)
            door_y = (wy0 + wy1) / 2
            room_y = (ry0 + ry1) / 2
            visits.append((dx + 0.5, door_y, room_y, (dx, wy0, dx + 1.0, wy1)))
    rng.shuffle(visits)
    n_visit = rng.choice([1, 2])
    route_visits = sorted(visits[:n_visit], key=lambda v: v[0])
    for v in visits[n_visit:]:
        world.doors.append(v[3])
    out = [(1.0, yc)]
    for dxc, door_y, room_y, _ in route_visits:
        out += room_visit(dxc, yc, door_y, room_y)
    out.append((length - 1.0, yc))
    back = [(1.0, yc), (length / 2, yc)]
    return world, out, back


def corridor(rng):
    length = rng.uniform(20, 30)
    cw = rng.uniform(1.6, 2.4)
    h = 10.0
    world = World(length, h, solid=True)
    y0 = h / 2 - cw / 2
    world.box(WALL, y0, length - WALL, y0 + cw, False)
    yc = h / 2
    # Recesses (doorways, alcoves) on both sides every 2-5 m.
    x = rng.uniform(1.5, 3.0)
    while x < length - 2.0:
        w, d = rng.uniform(0.8, 1.5), rng.uniform(0.3, 1.0)
        if rng.random() < 0.5:
            world.box(x, y0 - d, x + w, y0, False)
        else:
            world.box(x, y0 + cw, x + w, y0 + cw + d, False)
        x += w + rng.uniform(2.0, 5.0)
    # Two side rooms, one visited.
    visits = []
    for south in (True, False):
        rx = rng.uniform(3.0, length - 7.0)
        rw, rd = rng.uniform(3.0, 5.0), rng.uniform(2.5, 3.5)
        if south:
            world.box(rx, y0 - WALL - rd, rx + rw, y0 - WALL, False)
            door = (rx + rw / 2 - 0.5, y0 - WALL, rx + rw / 2 + 0.5, y0)
            room_y = y0 - WALL - rd / 2
        else:
            world.box(rx, y0 + cw + WALL, rx + rw, y0 + cw + WALL + rd, False)
            door = (rx + rw / 2 - 0.5, y0 + cw, rx + rw / 2 + 0.5, y0 + cw + WALL)
            room_y = y0 + cw + WALL + rd / 2
        world.box(*door, value=False)
        # a cabinet in the room
        world.box(rx + 0.3, room_y - 0.3, rx + 0.9, room_y + 0.3)
        visits.append((rx + rw / 2, (door[1] + door[3]) / 2, room_y, door))
    rng.shuffle(visits)
    world.doors.append(visits[1][3])
    dxc, door_y, room_y, _ = visits[0]
    out = [(1.0, yc)] + room_visit(dxc, yc, door_y, room_y) + [(length - 1.0, yc)]
    back = [(1.0, yc), (length / 2, yc)]
    return world, out, back


def loop(rng):
    w_m, h_m = rng.uniform(16, 24), rng.uniform(12, 16)
    cw = rng.uniform(2.2, 3.0)
    world = World(w_m, h_m)
    world.border()
    world.box(WALL + cw, WALL + cw, w_m - WALL - cw, h_m - WALL - cw)
    # Pillars against the outer walls.
    for _ in range(rng.randint(3, 6)):
        side = rng.randrange(4)
        s = rng.uniform(0.3, 0.6)
        if side == 0:
            x = rng.uniform(2, w_m - 2)
            world.box(x, WALL, x + s, WALL + s)
        elif side == 1:
            x = rng.uniform(2, w_m - 2)
            world.box(x, h_m - WALL - s, x + s, h_m - WALL)
        elif side == 2:
            y = rng.uniform(2, h_m - 2)
            world.box(WALL, y, WALL + s, y + s)
        else:
            y = rng.uniform(2, h_m - 2)
            world.box(w_m - WALL - s, y, w_m - WALL, y + s)
    c = WALL + cw / 2
    lap = [(c, c), (w_m - c, c), (w_m - c, h_m - c), (c, h_m - c), (c, c)]
    # Start mid-way along the south side, drive a lap and a half.
    start = (w_m / 2, c)
    out = [start] + lap[1:]
    back = lap[1:3] + [(w_m / 2, h_m - c)]
    return world, out, back


WORLDS = {"office": office, "corridor": corridor, "loop": loop}


def write_waypoints(path, points):
    with open(path, "w") as f:
        for x, y in points:
            f.write(f"{x:.3f} {y:.3f}\n")


def read_truth_scans(path):
    """The simulator's --truth-scans file: stamps (N), poses (N, 3), laser pose (3,), ranges
    (N, n), object index per ray (N, n)."""
    stamps, poses, ranges, objects = [], [], [], []
    laser = None
    with open(path) as f:
        for line in f:
            v = line.split()
            n = int(v[7])
            stamps.append(float(v[0]))
            poses.append([float(v[1]), float(v[2]), float(v[3])])
            laser = (float(v[4]), float(v[5]), float(v[6]))
            ranges.append([float(x) for x in v[8:8 + n]])
            objects.append([int(x) for x in v[8 + n:8 + 2 * n]])
    return (np.array(stamps), np.array(poses), np.array(laser), np.array(ranges, dtype=np.float32),
            np.array(objects, dtype=np.int16))


def waypoint_times(waypoints, stamps, poses, tolerance=0.15):
    """First time the truth comes within `tolerance` of each waypoint, in order."""
    times, k = [], 0
    for wx, wy in waypoints:
        d = np.hypot(poses[k:, 0] - wx, poses[k:, 1] - wy)
        hit = np.nonzero(d < tolerance)[0]
        if len(hit) == 0:
            times.append(float("inf"))
            continue
        k += int(hit[0])
        times.append(float(stamps[k]))
    return times


def draw_events(rng, kind, world, waypoints, n_out, stamps, poses):
    """The events of a scenario, given a dry run's truth (stamps, poses) without them.
    Returns (kidnap or None, objects as dicts); events fall on the way back (after waypoint
    n_out - 1 is reached) and at least 20 s before the end."""
    times = waypoint_times(waypoints, stamps, poses)
    t_back = times[n_out - 1]
    t_end = float(stamps[-1])
    if not (t_back + 25.0 < t_end):
        return None, []
    lo, hi = t_back + 3.0, t_end - 20.0

    def pose_at(t):
        i = int(np.searchsorted(stamps, t))
        i = min(i, len(stamps) - 1)
        return poses[i]

    def next_waypoint(t):
        for k, tk in enumerate(times):
            if tk > t:
                return waypoints[k]
        return waypoints[-1]

    if kind == "kidnap":
        for _ in range(400):
            t = rng.uniform(lo, hi)
            x, y, th = pose_at(t)
            d = rng.uniform(0.3, 3.0)
            phi = rng.uniform(-math.pi, math.pi)
            dth = math.radians(rng.uniform(0.0, 90.0)) * rng.choice([-1, 1])
            nx, ny = x + d * math.cos(phi), y + d * math.sin(phi)
            if world.clearance(nx, ny) < 0.4:
                continue
            if not world.segment_clear((nx, ny), next_waypoint(t), 0.3):
                continue
            return {"t": t, "dx": nx - x, "dy": ny - y, "dtheta": dth, "distance": d}, []
        return None, []
    objects = []
    # People crossing ahead of the robot.
    for _ in range(rng.randint(1, 3)):
        for _ in range(100):
            t = rng.uniform(lo, hi)
            x, y, th = pose_at(t)
            ahead = rng.uniform(1.5, 5.0)
            cx, cy = x + ahead * math.cos(th), y + ahead * math.sin(th)
            if world.clearance(cx, cy) < 0.4:
                continue
            nx, ny = -math.sin(th), math.cos(th)
            ends = []
            for sgn in (1, -1):
                s = 0.0
                while s < 4.0 and world.clearance(cx + sgn * (s + 0.05) * nx,
                                                  cy + sgn * (s + 0.05) * ny) > 0.35:
                    s += 0.05
                ends.append((cx + sgn * s * nx, cy + sgn * s * ny))
            span = math.hypot(ends[0][0] - ends[1][0], ends[0][1] - ends[1][1])
            if span < 1.0:
                continue
            speed = rng.uniform(0.6, 1.4)
            a, b = (ends[1], ends[0]) if rng.random() < 0.5 else (ends[0], ends[1])
            # The person reaches the robot's line when the robot is there.
            t0 = t - 0.5 * span / speed
            objects.append({"kind": "person", "shape": "disc", "t0": t0, "t1": t0 + span / speed,
                            "a": a, "b": b, "r": 0.25})
            break
    # A box parked beside the route, then removed.
    for _ in range(100):
        t = rng.uniform(lo, hi - 5.0)
        x, y, th = pose_at(t)
        ahead = rng.uniform(1.5, 4.0)
        side = rng.choice([-1, 1]) * rng.uniform(0.6, 1.2)
        bx = x + ahead * math.cos(th) - side * math.sin(th)
        by = y + ahead * math.sin(th) + side * math.cos(th)
        half = rng.uniform(0.15, 0.35)
        if world.clearance(bx, by) < half + 0.15:
            continue
        t0 = rng.uniform(lo - 3.0, t)
        t1 = t + rng.uniform(3.0, 15.0)
        a = (bx - half * math.cos(th), by - half * math.sin(th))
        b = (bx + half * math.cos(th), by + half * math.sin(th))
        objects.append({"kind": "box", "shape": "bar", "t0": t0, "t1": t1, "a": a, "b": b,
                        "r": half})
        break
    # A door of a room the route does not enter opens (closed from the start) or closes.
    if world.doors:
        x0, y0, x1, y1 = world.doors[rng.randrange(len(world.doors))]
        if x1 - x0 > y1 - y0:  # a doorway in a wall along x
            a, b = (x0 + 0.05, (y0 + y1) / 2), (x1 - 0.05, (y0 + y1) / 2)
        else:
            a, b = ((x0 + x1) / 2, y0 + 0.05), ((x0 + x1) / 2, y1 - 0.05)
        t = rng.uniform(lo, hi)
        if rng.random() < 0.5:
            objects.append({"kind": "door", "shape": "bar", "t0": 0.0, "t1": t, "a": a, "b": b,
                            "r": 0.05})
        else:
            objects.append({"kind": "door", "shape": "bar", "t0": t, "t1": 1e6, "a": a, "b": b,
                            "r": 0.05})
    return None, objects


def write_objects(path, objects):
    with open(path, "w") as f:
        for o in objects:
            if o["shape"] == "disc":
                f.write("disc %.3f %.3f %.3f %.3f %.3f %.3f %.3f  # %s\n" % (
                    o["t0"], o["t1"], o["a"][0], o["a"][1], o["b"][0], o["b"][1], o["r"],
                    o["kind"]))
            else:
                f.write("bar %.3f %.3f %.3f %.3f %.3f %.3f %.3f  # %s\n" % (
                    o["t0"], o["t1"], o["a"][0], o["a"][1], o["b"][0], o["b"][1], o["r"],
                    o["kind"]))
