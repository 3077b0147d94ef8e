#!/usr/bin/env python3
"""Draws the exploration benchmark's worlds (standard library only), 0.05 m per pixel, white free,
black wall, a 0.2 m wall round each:
  office.png  16 m x 10 m: a 2 m corridor along the middle, four rooms on each side behind 1 m
              doors.
  loop.png    24 m x 16 m: a 2.5 m wide corridor round a solid block (one large loop).
Run from this directory: python3 draw_worlds.py"""
import struct
import zlib

RES = 0.05


def px(m):
    return int(round(m / RES))


def canvas(w_m, h_m):
    w, h = px(w_m), px(h_m)
    img = [[255] * w for _ in range(h)]
    return img, w, h


def box(img, x0, y0, x1, y1, v=0):
    """Fills [x0, x1) x [y0, y1) (m, from the lower left)."""
    h = len(img)
    for y in range(px(y0), px(y1)):
        for x in range(px(x0), px(x1)):
            img[h - 1 - y][x] = v


def border(img, w_m, h_m, t=0.2):
    box(img, 0, 0, w_m, t)
    box(img, 0, h_m - t, w_m, h_m)
    box(img, 0, 0, t, h_m)
    box(img, w_m - t, 0, w_m, h_m)


def write_png(path, img):
    h, w = len(img), len(img[0])
    raw = b"".join(b"\x00" + bytes(row) for row in img)

    def chunk(kind, data):
        c = struct.pack(">I", len(data)) + kind + data
        return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def office():
    W, H, t = 16.0, 10.0, 0.2
    img, _, _ = canvas(W, H)
    border(img, W, H)
    # corridor y in [4, 6]; walls along it with a 1 m door per room
    for y0 in (4.0 - t, 6.0):
        box(img, 0, y0, W, y0 + t)
    rooms = 4
    width = W / rooms
    for k in range(rooms):
        x = k * width
        if k > 0:
            box(img, x - t / 2, 0, x + t / 2, 4.0)      # partitions below
            box(img, x - t / 2, 6.0, x + t / 2, H)      # and above
        door = x + width / 2 - 0.5
        box(img, door, 4.0 - t, door + 1.0, 4.0, 255)  # doors below
        box(img, door, 6.0, door + 1.0, 6.0 + t, 255)  # and above
    write_png("office.png", img)


def loop():
    W, H = 24.0, 16.0
    img, _, _ = canvas(W, H)
    border(img, W, H)
    box(img, 2.7, 2.7, W - 2.7, H - 2.7)  # the block: a 2.5 m corridor round it
    write_png("loop.png", img)


if __name__ == "__main__":
    office()
    loop()
