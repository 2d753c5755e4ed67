#!/usr/bin/env python3
"""PSNR of two same-sized images over the left third of the columns and over the rest.

Used for the `builtin:bricks` table in docs/guide/lighting.md, whose left third sees the wall at
about 50 degrees and the rest at grazing angles:

    python3 scripts/psnr_split.py r/reference.png r/aniso16.png --background 40,46,56

Pixels where both images show the background colour (the scene's, 8-bit sRGB) are left out, as
`texel compare` leaves out uncovered pixels. Needs Pillow (`pip install pillow`).
"""

import argparse
import math

from PIL import Image


def psnr(a, b, x0, x1, background):
    w, h = a.size
    pa, pb = a.load(), b.load()
    se = n = 0
    for y in range(h):
        for x in range(x0, x1):
            p, q = pa[x, y], pb[x, y]
            if p == background and q == background:
                continue
            se += sum((p[c] - q[c]) ** 2 for c in range(3))
            n += 3
    if n == 0:
        return float("nan")
    return float("inf") if se == 0 else 10 * math.log10(255 * 255 / (se / n))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--background", default="40,46,56", help="r,g,b of uncovered pixels")
    args = ap.parse_args()
    a = Image.open(args.a).convert("RGB")
    b = Image.open(args.b).convert("RGB")
    if a.size != b.size:
        raise SystemExit(f"sizes differ: {a.size} and {b.size}")
    bg = tuple(int(v) for v in args.background.split(","))
    w = a.size[0]
    print(
        "all %.2f left-third %.2f rest %.2f"
        % (psnr(a, b, 0, w, bg), psnr(a, b, 0, w // 3, bg), psnr(a, b, w // 3, w, bg))
    )


if __name__ == "__main__":
    main()
