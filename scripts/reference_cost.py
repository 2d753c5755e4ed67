#!/usr/bin/env python3
"""What the default reference of the unlit built-in scenes costs, and how close it comes.

  target/python-venv/bin/python scripts/reference_cost.py [SCENE ...] [--size WxH] [--threads T]

For each scene (default: the unlit built-ins) it renders, timed, the reference with the default
plan (at least 256 samples a pixel, more until the 95 % interval of the displayed value is within
half an 8-bit step, at most 65536) and a fixed 256-sample one, both with the default seed, and a
fixed 4096-sample one with another seed (independent). It prints each one's time and mean samples
a pixel and, for the first two, the share of pixels whose displayed value (clipped, sRGB, 8-bit
units, not rounded) lies within half a step of the 4096-sample reference's in every channel: the
unlit goal of the reference's error bars (docs/guide/measuring.md). Needs the Python package
(python/).
"""
import argparse
import time

import numpy as np

import texel

UNLIT = ["ground", "ground-rotated", "zoneplate", "cube", "sphere", "globe", "globe-equirect",
         "triangle", "knot"]


def display(x):
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055) * 255.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scenes", nargs="*")
    ap.add_argument("--size", default="320x180")
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    size = tuple(int(v) for v in a.size.split("x"))
    scenes = a.scenes or [f"builtin:{s}" for s in UNLIT]
    print("| scene | reference | s | mean spp | within half a step of 4096 |")
    print("|---|---|--:|--:|--:|")
    for scene in scenes:
        runs = {}
        for name, kw in (("default", {}), ("fixed 256", {"spp": 256, "max_spp": 256}),
                         ("fixed 4096", {"spp": 4096, "max_spp": 4096, "seed": 2})):
            t0 = time.time()
            r = texel.reference_estimate(scene, size=size, threads=a.threads, **kw)
            runs[name] = (r, time.time() - t0)
        truth = runs["fixed 4096"][0]
        shown = display(truth["linear"][..., :3])
        for name, (r, secs) in runs.items():
            if r is truth:
                within = "-"
            else:
                d = np.abs(display(r["linear"][..., :3]) - shown).max(-1)
                within = f"{(d <= 0.5).mean() * 100:.1f} %"
            print(f"| {scene} | {name} | {secs:.1f} | {r['spp'].mean():.0f} | {within} |",
                  flush=True)


if __name__ == "__main__":
    main()
