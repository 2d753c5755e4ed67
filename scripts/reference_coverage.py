#!/usr/bin/env python3
"""Do the reference's error bars cover a brute force with 64 times each pixel's samples?

  target/python-venv/bin/python scripts/reference_coverage.py [SCENE] [--size WxH]
        [--pixels K] [--factor F] [--seed S] [--threads T]

Renders SCENE's reference with the default plan (at least 256 samples a pixel, more until the
95 % interval of the displayed value is within half an 8-bit step, at most 65536) and seed S.
Then it draws K pixels at random (a fixed generator) among those the reference does not show
black, and gives each a brute-force estimate of its own with F times the samples that pixel got
in the reference (F = 64 by default), from independent seeds, through 1-pixel scissor
rectangles: `texel.reference_estimate(..., tolerance=0)` calls of at most 65536 samples each,
combined by their sample counts. It prints, per channel and over the K pixels, the share whose
brute force lies within the reference's reported 95 % interval (Student's t with the pixel's
passes less one degrees of freedom, as the reference's own convergence test) and within 1.96
standard errors, with a binomial 95 % margin for the share; the mean and the largest ratio of
|brute - reference| to the reference's standard error; and the samples behind the brute force.

A call with tolerance 0 stops early only for a pixel whose interval lies wholly above 1 (the
display clips it); the script counts the samples each call returns and goes on for such a pixel
with calls of a fixed count (minimum = maximum, at most 4096), so every brute force has F times
its pixel's reference samples. It also gives the share for the pixels whose reference interval
does not lie wholly above 1 (what the display does not clip).

Defaults: scenes/glints.toml at 160x90 (the glossy plane of docs/guide/measuring.md), 600
pixels, F = 64, seed 1, 2 threads. Needs the Python package (python/, docs/guide/python.md).
"""
import argparse
import math
import time

import numpy as np

import texel

# One call's most samples: the library's MAX_ADAPTIVE_SPP; a plan's minimum is at most 4096.
MAX_CALL = 65536
MAX_MIN = 4096
# Samples a pass of the default plan's minimum (256 = 8 passes of 32) holds.
PER_PASS = 32


def t_975(dof):
    """Student's t 0.975 quantile, the reference's own table (texel_raster::adaptive::t_975)."""
    table = [(1, 12.706), (2, 4.303), (3, 3.182), (4, 2.776), (5, 2.571), (6, 2.447),
             (7, 2.365), (8, 2.306), (9, 2.262), (10, 2.228), (12, 2.179), (15, 2.131),
             (20, 2.086), (30, 2.042), (40, 2.021), (60, 2.000), (120, 1.980), (1000, 1.962)]
    t = 1.960
    for d, q in reversed(table):
        if dof >= d:
            return q
    return t


def brute(scene, size, x, y, samples, seed, threads):
    """A 1-pixel estimate with `samples` samples: (mean, spp)."""
    total, spp_sum, call = np.zeros(4), 0, 0
    fixed = False
    while spp_sum < samples:
        left = samples - spp_sum
        # Calls of up to MAX_CALL samples with tolerance 0 refine until their maximum, except
        # where the interval lies wholly above 1 (the display clips it, so the reference calls
        # the pixel converged); from then on, calls whose minimum is their maximum.
        n = min(left, MAX_MIN) if fixed else min(left, MAX_CALL)
        r = texel.reference_estimate(
            scene, spp=min(n, MAX_MIN), max_spp=n, tolerance=0.0, seed=seed + call,
            size=size, threads=threads, scissor=(x, y, x + 1, y + 1))
        got = int(r["spp"][0, 0])
        fixed = fixed or got < n
        total += r["linear"][0, 0].astype(np.float64) * got
        spp_sum += got
        call += 1
    return total / spp_sum, spp_sum


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene", nargs="?", default="scenes/glints.toml")
    ap.add_argument("--size", default="160x90")
    ap.add_argument("--pixels", type=int, default=600)
    ap.add_argument("--factor", type=int, default=64)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    size = tuple(int(v) for v in a.size.split("x"))

    t0 = time.time()
    ref = texel.reference_estimate(a.scene, seed=a.seed, size=size, threads=a.threads)
    print(f"reference: {time.time() - t0:.1f} s, mean {ref['spp'].mean():.0f} samples a pixel, "
          f"{ref['converged'].mean() * 100:.1f} % converged", flush=True)
    shown = ref["linear"][..., :3].sum(-1) > 0
    ys, xs = np.nonzero(shown)
    rng = np.random.default_rng(12345)
    pick = rng.choice(len(xs), size=min(a.pixels, len(xs)), replace=False)

    rows = []
    t0 = time.time()
    for i, k in enumerate(pick):
        x, y = int(xs[k]), int(ys[k])
        s = int(ref["spp"][y, x])
        # Independent seeds: far from the reference's and from every other pixel's.
        seed = 1_000_000 + 10_000 * i
        mean, got = brute(a.scene, size, x, y, a.factor * s, seed, a.threads)
        rows.append((ref["linear"][y, x, :3], ref["std_error"][y, x, :3], s, mean[:3], got))
        if (i + 1) % 50 == 0:
            print(f"  {i + 1} pixels, {time.time() - t0:.0f} s", flush=True)

    n = len(rows)
    m = np.array([r[0] for r in rows], dtype=np.float64)
    se = np.array([r[1] for r in rows], dtype=np.float64)
    spp = np.array([r[2] for r in rows])
    b = np.array([r[3] for r in rows])
    got = np.array([r[4] for r in rows])
    t = np.array([t_975(int(s) // PER_PASS - 1) for s in spp])[:, None]
    z = np.abs(b - m) / np.where(se > 0, se, np.nan)
    d = np.abs(b - m)
    print(f"{n} of {shown.sum()} shown pixels; reference samples a pixel: mean {spp.mean():.0f}, "
          f"median {np.median(spp):.0f}, max {spp.max()}")
    ratio = got / spp
    print(f"brute force: {got.sum():.3g} samples, {ratio.min():.1f}x to {ratio.max():.1f}x each "
          f"pixel's reference samples; {time.time() - t0:.0f} s")
    # Pixels whose reference interval lies wholly above 1 in every channel: the display clips
    # them, and the reference stops there however wide the interval is.
    clipped = (m - t * se > 1.0).all(-1)
    for part, rows_of in (("all", np.ones(n, bool)), ("not clipped", ~clipped)):
        k = rows_of.sum()
        margin = 1.96 * math.sqrt(0.95 * 0.05 / max(k, 1))
        print(f"{part} ({k} pixels):")
        for c, name in enumerate("RGB"):
            within_t = (d[rows_of, c] <= t[rows_of, 0] * se[rows_of, c]).mean()
            within_z = (d[rows_of, c] <= 1.96 * se[rows_of, c]).mean()
            zc = z[rows_of, c][np.isfinite(z[rows_of, c])]
            print(f"  {name}: brute force within the reported 95 % interval on "
                  f"{within_t * 100:.1f} % (+-{margin * 100:.1f}), within 1.96 SE on "
                  f"{within_z * 100:.1f} %; |brute - reference| / SE mean {zc.mean():.2f}, "
                  f"largest {zc.max():.1f}; zero-SE pixels {(se[rows_of, c] == 0).sum()}")


if __name__ == "__main__":
    main()
