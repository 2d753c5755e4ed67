#!/usr/bin/env python3
"""The exact reference against a brute force of 65536 samples a pixel.

  scripts/exact_check.py [SCENE ...] [--size 320x180] [--seeds 16] [--threads 2]

For each scene (default: the unlit built-ins whose surfaces it integrates: ground,
ground-rotated, zoneplate, cube) it renders `texel.reference_estimate(..., exact=True)` and
`--seeds` independent 4096-sample references (seeds 1001, 1002, ...; 16 of them make 65536
samples a pixel), combines those into one brute force (the mean of the means, its standard error
the root of the summed squared standard errors over the number of seeds), and prints, over the
exact pixels: the share inside the brute force's 95 % interval on all of R, G and B (1.96
standard errors; a pixel whose passes all agree has a zero-width interval, and counts as inside
when it differs by less than 1e-7), the mean absolute difference in linear light and on the sRGB
display (in 8-bit steps), the brute force's own mean standard error, and both times.

Needs the Python package (`pip install ./python`) and numpy.
"""
import argparse
import time

import numpy as np

import texel


def srgb(x):
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scenes", nargs="*", default=["ground", "ground-rotated", "zoneplate", "cube"])
    p.add_argument("--size", default="320x180")
    p.add_argument("--seeds", type=int, default=16)
    p.add_argument("--threads", type=int, default=2)
    a = p.parse_args()
    w, h = (int(v) for v in a.size.split("x"))
    for name in a.scenes:
        scene = name if ":" in name or "/" in name else f"builtin:{name}"
        t0 = time.perf_counter()
        ex = texel.reference_estimate(
            scene, spp=256, max_spp=256, size=(w, h), threads=a.threads, exact=True
        )
        t_exact = time.perf_counter() - t0
        means, ses = [], []
        t0 = time.perf_counter()
        for k in range(a.seeds):
            r = texel.reference_estimate(
                scene, spp=4096, max_spp=4096, seed=1001 + k, size=(w, h), threads=a.threads
            )
            means.append(r["linear"].astype(np.float64))
            ses.append(r["std_error"].astype(np.float64))
        t_brute = time.perf_counter() - t0
        m = np.mean(means, axis=0)
        se = np.sqrt(np.sum(np.square(ses), axis=0)) / a.seeds
        exact = ex["exact"]
        d = (ex["linear"].astype(np.float64) - m)[..., :3]
        inside = (np.abs(d) <= 1.96 * se[..., :3] + 1e-7).all(-1)
        shown = np.abs(srgb(ex["linear"][..., :3].astype(np.float64)) - srgb(m[..., :3])) * 255
        print(
            f"{name}: {100 * exact.mean():.2f} % exact; inside the 95 % interval "
            f"{100 * inside[exact].mean():.2f} %; mean |diff| {255 * np.abs(d)[exact].mean():.4f}/255 "
            f"linear, {shown[exact].mean():.4f} display steps; brute-force mean standard error "
            f"{255 * se[..., :3][exact].mean():.4f}/255; exact {t_exact:.1f} s, "
            f"brute force {t_brute:.0f} s ({a.seeds * 4096} samples a pixel)"
        )


if __name__ == "__main__":
    main()
