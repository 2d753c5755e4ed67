#!/usr/bin/env python3
"""Benchmarks of the Python package: Texture.sample on 10^6 points against OpenCV's remap, the
expensive filters' throughput, and distributed.render on one and two local Ray workers.

Run in an environment with the package, OpenCV and Ray:

    python -m venv target/python-venv
    target/python-venv/bin/pip install './python[ray]' opencv-python-headless
    target/python-venv/bin/python scripts/python_bench.py [--threads 2] [--frames 32]

Prints one Markdown table per part. Times are the median of --repeats runs after one warm-up.
"""

import argparse
import os
import platform
import statistics
import time

import numpy as np


def median_seconds(fn, repeats):
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def points(n_side, size):
    """A rotated, scaled grid of n_side^2 points over a size^2 texture, with its footprint."""
    j, i = np.mgrid[0:n_side, 0:n_side].astype(np.float32)
    a = np.deg2rad(30.0)
    scale = 1.3 * size / n_side  # texels per output pixel: mild minification
    x = (np.cos(a) * i - np.sin(a) * j) * scale
    y = (np.sin(a) * i + np.cos(a) * j) * scale
    dx = np.array([np.cos(a) * scale, np.sin(a) * scale], dtype=np.float32) / size
    dy = np.array([-np.sin(a) * scale, np.cos(a) * scale], dtype=np.float32) / size
    return x.astype(np.float32), y.astype(np.float32), dx, dy


def bench_sample(args):
    import cv2
    import texel

    cv2.setNumThreads(args.threads)
    size, n = 1024, 1000
    rng = np.random.default_rng(0)
    image = (rng.random((size, size, 4)) * 255).astype(np.uint8)
    tex = texel.Texture(image, color="linear", address="repeat")
    x, y, dx, dy = points(n, size)
    # texel's uv: texel centres at (i + 0.5) / size; OpenCV's map: pixel centres at integers.
    uv = np.ascontiguousarray(np.stack([(x + 0.5) / size, (y + 0.5) / size], axis=-1))
    duv_dx = np.ascontiguousarray(np.broadcast_to(dx, uv.shape))
    duv_dy = np.ascontiguousarray(np.broadcast_to(dy, uv.shape))
    remap = median_seconds(
        lambda: cv2.remap(image, x, y, cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP), args.repeats
    )
    rows = [("OpenCV remap, bilinear, BORDER_WRAP (uint8 out)", remap)]
    for f in ["bilinear", "trilinear", "aniso16", "ewa"]:
        t = median_seconds(lambda: tex.sample(uv, duv_dx, duv_dy, filter=f), args.repeats)
        rows.append((f"texel Texture.sample, {f} (float32 linear out)", t))
    print(f"\n10^6 points on a 1024x1024 RGBA8 texture, {args.threads} threads")
    print("\n| sampler | ms | Mpoints/s | x remap |\n|---|--:|--:|--:|")
    for name, t in rows:
        print(f"| {name} | {t * 1e3:.1f} | {n * n / t / 1e6:.1f} | {t / remap:.2f} |")


def bench_distributed(args):
    import ray
    import texel
    from texel import distributed

    jobs = [{"scene": "builtin:ground", "filter": "aniso16", "size": (640, 360)}] * args.frames
    rows = []
    for workers in (1, 2):
        ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False)
        try:
            distributed.render(jobs[:workers])  # start the workers
            t0 = time.perf_counter()
            distributed.render(jobs)
            rows.append((workers, time.perf_counter() - t0))
        finally:
            ray.shutdown()
    t0 = time.perf_counter()
    for j in jobs:
        texel.render(threads=1, **j)
    local = time.perf_counter() - t0
    print(f"\n{args.frames} frames of builtin:ground at 640x360, aniso16, one thread per job")
    print("\n| run | s | frames/s | speed-up |\n|---|--:|--:|--:|")
    print(f"| texel.render in a loop, 1 thread | {local:.2f} | {args.frames / local:.1f} | - |")
    for workers, t in rows:
        print(
            f"| distributed.render, {workers} Ray worker{'s' if workers > 1 else ''} | {t:.2f} | "
            f"{args.frames / t:.1f} | {rows[0][1] / t:.2f} |"
        )


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--threads", type=int, default=os.cpu_count())
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--frames", type=int, default=32)
    p.add_argument("--part", choices=["sample", "distributed", "all"], default="all")
    args = p.parse_args()
    # texel's threads (rayon's pool) and OpenCV's alike.
    os.environ["RAYON_NUM_THREADS"] = str(args.threads)
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores")
    if args.part in ("sample", "all"):
        bench_sample(args)
    if args.part in ("distributed", "all"):
        bench_distributed(args)


if __name__ == "__main__":
    main()
