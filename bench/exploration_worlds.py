"""Generated worlds of the exploration benchmark (scripts/benchmark-exploration), drawn from one
seed: an office with the places a real building has that a laser reads ambiguously.

  office   a corridor (1.8-2.4 m) with rooms (3-5 m wide, 3-4 m deep) on both sides behind 1 m
           doors (bench/scenarios.py's World);
  glass    1-3 rooms have a glass front toward the corridor instead of a wall: `glass` regions
           0.2 m thick along the wall line, each beam passing with a probability drawn in
           [0.3, 0.7] per pane;
  clutter  1-3 rooms hold clutter against their far wall (shelves, plants, chairs): a `clutter`
           region 1-2 m long and 0.6-1.0 m deep with a range scatter drawn in [0.15, 0.4] m;
  people   1-2 people walk the corridor end to end and back at 0.5-1.0 m/s for the whole run
           (`disc` objects, radius 0.25 m).

write(seed, directory, duration) writes world.png and objects.txt and returns the world's
description: image, resolution, start pose (the image's lower-left corner is the map origin,
map_centered false), and the regions drawn."""

import math
import os
import random

from scenarios import RES, WALL, World

GLASS_PASS = (0.3, 0.7)
CLUTTER_SIGMA = (0.15, 0.4)


def office_with_regions(rng, duration):
    length = rng.uniform(16, 22)
    cw = rng.uniform(1.8, 2.4)
    depth = rng.uniform(3.0, 4.0)
    h = 2 * depth + cw + 3 * WALL
    world = World(length, h)
    world.border()
    y_lo = WALL + depth
    y_hi = y_lo + WALL + cw
    yc = y_lo + WALL + cw / 2
    rooms = []  # (x0, x1, south, door x0)
    for south in (True, False):
        wy0 = y_lo if south else y_hi
        world.box(0, wy0, length, wy0 + WALL)
        x = WALL
        while length - WALL - x > 2.5:
            w = min(rng.uniform(3.0, 5.0), length - WALL - x)
            if length - WALL - (x + w) < 2.5:
                w = length - WALL - x
            x0, x1 = x, x + w
            x = x1
            if x < length - WALL - 0.1:
                world.box(x, WALL if south else y_hi + WALL, x + WALL,
                          y_lo if south else h - WALL)
                x += WALL
            door = rng.uniform(x0 + 0.4, x1 - 1.4)
            world.box(door, wy0, door + 1.0, wy0 + WALL, False)
            rooms.append((x0, x1, south, door))
    objects = []
    order = list(range(len(rooms)))
    rng.shuffle(order)
    n_glass = rng.randint(1, min(3, len(rooms)))
    n_clutter = rng.randint(1, min(3, len(rooms)))
    for k in order[:n_glass]:
        x0, x1, south, door = rooms[k]
        wy0 = y_lo if south else y_hi
        wy = wy0 + WALL / 2
        p = rng.uniform(*GLASS_PASS)
        # The wall on either side of the door becomes glass (the partitions' ends stay wall).
        for a, b in ((x0, door), (door + 1.0, x1)):
            if b - a < 0.3:
                continue
            world.box(a, wy0, b, wy0 + WALL, False)
            objects.append({"kind": "glass", "a": (a + 0.1, wy), "b": (b - 0.1, wy), "r": 0.025,
                            "value": p})
    for k in order[-n_clutter:]:
        x0, x1, south, door = rooms[k]
        length_c = rng.uniform(1.0, min(2.0, x1 - x0 - 1.0))
        r = rng.uniform(0.3, 0.5)
        cx0 = rng.uniform(x0 + 0.3 + r, x1 - 0.3 - r - length_c)
        far = WALL + 0.1 + r if south else h - WALL - 0.1 - r
        objects.append({"kind": "clutter", "a": (cx0, far), "b": (cx0 + length_c, far), "r": r,
                        "value": rng.uniform(*CLUTTER_SIGMA)})
    for _ in range(rng.randint(1, 2)):
        y = yc + rng.uniform(-0.3, 0.3) * cw / 2
        speed = rng.uniform(0.5, 1.0)
        ends = [(1.0, y), (length - 1.0, y)]
        if rng.random() < 0.5:
            ends.reverse()
        leg = (length - 2.0) / speed
        # Somewhere along its walk at the start, at least 3 m from the robot.
        while True:
            t = -rng.uniform(0.0, leg)
            x = ends[0][0] + (ends[1][0] - ends[0][0]) * (-t / leg)
            if abs(x - 1.0) >= 3.0:
                break
        while t < duration:
            objects.append({"kind": "person", "t0": t, "t1": t + leg, "a": ends[0], "b": ends[1],
                            "r": 0.25})
            ends.reverse()
            t += leg
    start = (1.0, yc, 0.0)
    return world, objects, start


def write(seed, directory, duration):
    rng = random.Random(seed)
    world, objects, start = office_with_regions(rng, duration)
    os.makedirs(directory, exist_ok=True)
    image = os.path.join(directory, "world.png")
    world.write_png(image)
    path = os.path.join(directory, "objects.txt")
    with open(path, "w") as f:
        f.write("# bench/exploration_worlds.py, seed %d\n" % seed)
        for o in objects:
            if o["kind"] == "person":
                f.write("disc %.3f %.3f %.3f %.3f %.3f %.3f %.3f  # person\n" % (
                    o["t0"], o["t1"], o["a"][0], o["a"][1], o["b"][0], o["b"][1], o["r"]))
            else:
                f.write("%s %.3f %.3f %.3f %.3f %.3f %.3f\n" % (
                    o["kind"], o["a"][0], o["a"][1], o["b"][0], o["b"][1], o["r"], o["value"]))
    return {"image": image, "objects": path, "resolution": RES, "start": start,
            "size": (world.w_m, world.h_m),
            "glass": sum(o["kind"] == "glass" for o in objects),
            "clutter": sum(o["kind"] == "clutter" for o in objects),
            "people": len({(o["a"][1]) for o in objects if o["kind"] == "person"})}


if __name__ == "__main__":
    import sys
    print(write(int(sys.argv[1]), sys.argv[2], float(sys.argv[3]) if len(sys.argv) > 3 else 900))
