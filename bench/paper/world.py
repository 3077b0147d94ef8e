#!/usr/bin/python3
"""The world of the paper experiment (scripts/reproduce-paper): a floor plan, the robot's route and
the ground-truth regions that claims.json is evaluated on.

World (metres, origin at the lower-left corner, y up), 0.05 m per pixel:
  - a 3 m wide corridor loop inside the outer walls (32 m x 22 m), with pillars and alcoves so the
    laser always sees structure across the direction of travel;
  - inside the loop, behind closed walls, a room the robot never enters (west) and a room it sees
    into through a wide door but never enters (east);
  - the route: one lap around the loop to map it, then a second lap through the south corridor,
    where a person walks beside the robot (moving object) and, near the south-east corner, the
    robot is kidnapped 2 m ahead (odometry unaware), and on up the east corridor.

Writes world.png (black = wall), world.yaml (map_server metadata), waypoints.txt ("x y" per line)
and regions.json (the rectangles and fault parameters the analysis uses).
Usage: bench/paper/world.py OUT_DIR
"""
import json
import os
import sys

from PIL import Image, ImageDraw

RES = 0.05
W_M, H_M = 32.0, 22.0
WALL = 0.3


def main(out_dir):
    os.makedirs(out_dir, exist_ok=True)
    w, h = int(round(W_M / RES)), int(round(H_M / RES))
    img = Image.new("L", (w, h), 255)
    draw = ImageDraw.Draw(img)

    def box(x0, y0, x1, y1):
        """Fills [x0, x1] x [y0, y1] (metres) with wall."""
        draw.rectangle([int(round(x0 / RES)), int(round((H_M - y1) / RES)),
                        int(round(x1 / RES)) - 1, int(round((H_M - y0) / RES)) - 1], fill=0)

    # Outer walls.
    box(0, 0, W_M, WALL)
    box(0, H_M - WALL, W_M, H_M)
    box(0, 0, WALL, H_M)
    box(W_M - WALL, 0, W_M, H_M)
    # The block inside the loop: corridor 3 m wide.
    c = WALL + 3.0  # inner edge of the corridor
    bx0, by0, bx1, by1 = c, c, W_M - c, H_M - c
    box(bx0, by0, bx1, by0 + WALL)      # south wall of the block
    box(bx0, by1 - WALL, bx1, by1)      # north wall
    box(bx0, by0, bx0 + WALL, by1)      # west wall
    box(bx1 - WALL, by0, bx1, by1)      # east wall
    mid = 15.0
    box(mid, by0, mid + WALL, by1)      # the wall between the two rooms
    # East room: a 2.4 m door in the block's north wall (seen into, never entered).
    door = (21.0, 23.4)
    draw.rectangle([int(round(door[0] / RES)), int(round((H_M - by1) / RES)),
                    int(round(door[1] / RES)) - 1, int(round((H_M - by1 + WALL) / RES)) - 1],
                   fill=255)
    # Pillars (0.4 m) against the outer walls, and alcoves (0.6 m deep) in them.
    for x in (5.0, 11.0, 17.5, 24.0):
        box(x, WALL, x + 0.4, WALL + 0.4)
        box(x + 1.5, H_M - WALL - 0.4, x + 1.9, H_M - WALL)
    for y in (6.0, 12.5, 17.0):
        box(WALL, y, WALL + 0.4, y + 0.4)
        box(W_M - WALL - 0.4, y - 2.0, W_M - WALL, y - 1.6)
    for x0, x1 in ((8.0, 9.5), (20.0, 21.5)):  # alcoves: cut into the south outer wall's mass
        box(x0, WALL, x0 + 0.15, WALL + 0.6)
        box(x1 - 0.15, WALL, x1, WALL + 0.6)
    img.save(os.path.join(out_dir, "world.png"))
    with open(os.path.join(out_dir, "world.yaml"), "w") as f:
        f.write("image: world.png\nresolution: %.2f\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
                "occupied_thresh: 0.65\nfree_thresh: 0.196\n" % RES)

    lane = WALL + 1.5  # corridor centre line
    e, n = W_M - lane, H_M - lane
    route = [(lane, lane), (e, lane), (e, n), (lane, n), (lane, lane),  # lap 1
             (e - 2.5, lane), (e, lane + 2.5), (e, 14.0)]               # lap 2, part
    with open(os.path.join(out_dir, "waypoints.txt"), "w") as f:
        f.write("# x y (m): one lap of the corridor loop, then the south and east corridors\n")
        for x, y in route:
            f.write("%.2f %.2f\n" % (x, y))

    regions = {
        "resolution": RES, "width_m": W_M, "height_m": H_M,
        # Interior of the room the robot never enters nor sees into (walls excluded).
        "never_entered_room": [bx0 + WALL, by0 + WALL, mid, by1 - WALL],
        # Where the person walks beside the robot on lap 2 (south corridor), and how the simulator
        # puts it into the scans: ranges over a bearing window replaced by a constant distance.
        "moving_object": {"x_from": 6.0, "x_to": 14.0, "bearing_min_deg": 60.0,
                          "bearing_max_deg": 110.0, "distance_m": 1.0},
        # The kidnap on lap 2, near the south-east corner: true pose 2 m further east.
        "kidnap": {"x_at": 25.0, "dx": 2.0, "dy": 0.0, "dtheta": 0.0},
        # The scans placed 2 m off after the kidnap double the east corridor's walls there.
        "kidnap_region": [W_M - c - WALL - 2.5, 0.0, W_M, 14.0 + 3.0],
    }
    with open(os.path.join(out_dir, "regions.json"), "w") as f:
        json.dump(regions, f, indent=2)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
