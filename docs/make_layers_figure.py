#!/usr/bin/env python3
"""Builds docs/simul_layers.png (the README picture) from an offline run's layers/ directory.

Usage: python3 docs/make_layers_figure.py OUT_DIR/layers docs/simul_layers.png
Needs numpy and Pillow (PyPI). IC and EC are drawn from their .npy values stretched to the 99.5th
percentile of observed non-zero cells and thickened by one cell, so the thin lines along walls
stay visible at thumbnail size; the other layers are the runner's own PNGs.
"""
import os
import sys

import numpy as np
from PIL import Image, ImageDraw, ImageFilter

WIDTH = 420
PANELS = [
    ("composite", "composite: RGB = m(o), m(e), m(Theta)", False),
    ("pignistic", "pignistic BetP(o)", False),
    ("nonspecificity", "non-specificity NS", False),
    ("internal_conflict", "internal conflict IC (0..%.2f bits)", True),
    ("external_conflict", "external conflict EC (0..%.1f bits)", True),
    ("entropy", "entropy H(BetP)", False),
]


def stretched(layers, name):
    values = np.load(os.path.join(layers, name + ".npy"))
    observed = np.load(os.path.join(layers, "observed.npy")) > 0
    top = np.percentile(values[observed & (values > 0)], 99.5)
    grey = (255 * (1 - np.clip(values / top, 0, 1))).astype(np.uint8)[::-1]  # north up, dark = high
    return Image.fromarray(grey, "L").filter(ImageFilter.MinFilter(3)).convert("RGB"), top


def main(layers, out_path):
    tiles = []
    for name, label, from_npy in PANELS:
        if from_npy:
            image, top = stretched(layers, name)
            label = label % top
        else:
            image = Image.open(os.path.join(layers, name + ".png")).convert("RGB")
        height = int(image.size[1] * WIDTH / image.size[0])
        image = image.resize((WIDTH, height), Image.LANCZOS)
        tile = Image.new("RGB", (WIDTH, height + 22), "white")
        tile.paste(image, (0, 22))
        ImageDraw.Draw(tile).text((4, 5), label, fill="black")
        tiles.append(tile)
    tw, th = tiles[0].size
    sheet = Image.new("RGB", (3 * tw + 8, 2 * th + 4), "white")
    for i, tile in enumerate(tiles):
        sheet.paste(tile, ((i % 3) * (tw + 4), (i // 3) * (th + 4)))
    sheet.quantize(colors=128, method=Image.Quantize.MEDIANCUT).save(out_path, optimize=True)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
