#!/usr/bin/env python3
"""Run a benchmark and print the table of docs/benchmarks.md it backs, in that format.

Usage (from anywhere; runs in the repository root):
  scripts/bench_tables.py sampler   # "Sampler throughput": criterion, benches/sampler.rs
  scripts/bench_tables.py aniso     # "Anisotropic filters" and the structures' memory/build
  scripts/bench_tables.py threads [SCENE]
                                    # "Frame times by thread count": texel bench, 1 and 2
                                    # threads (default scene scenes/ground.toml)
  scripts/bench_tables.py demo      # texel demo's ground report as a table

sampler and aniso take `--exe PATH`: run an already built bench executable (e.g. an older commit's,
`target/release/deps/sampler-*`) instead of building this tree's, for before/after tables.

Each prints markdown on stdout and the command it ran on stderr. Numbers move by up to 15 % between
runs on a shared machine: keep a table as a `"kind": "table"` record in docs/benchmarks/ with the
machine next to it (the format is in scripts/bench.py), then run scripts/bench.py render.
"""
import json
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CRITERION = ["--warm-up-time", "1", "--measurement-time", "2", "--noplot"]


def run(cmd):
    print("$ " + " ".join(cmd), file=sys.stderr)
    out = subprocess.run(cmd, cwd=ROOT, check=True, stdout=subprocess.PIPE,
                         stderr=subprocess.DEVNULL, text=True)
    return out.stdout


def criterion(bench):
    """(throughputs in M elements/s by benchmark id, the bench's TABLE lines)."""
    if "--exe" in sys.argv:
        cmd = [sys.argv[sys.argv.index("--exe") + 1], "--bench"]
    else:
        cmd = ["cargo", "bench", "--locked", "-p", "texel-texture", "--bench", bench, "--"]
    out = run(cmd + CRITERION)
    thrpt, tables, last = {}, [], None
    units = {"ns": 1e-6, "µs": 1e-3, "ms": 1.0, "s": 1e3}
    rates = {"Kelem/s": 1e-3, "Melem/s": 1.0, "Gelem/s": 1e3, "elem/s": 1e-6}
    for line in out.splitlines():
        if line.startswith("TABLE "):
            tables.append(line.split()[1:])
            continue
        # A benchmark's id starts its first line; a long id stands alone, its time below it.
        m = re.match(r"^([a-z]\S*/\S+)(\s|$)", line)
        if m:
            last = m.group(1)
        m = re.search(r"^\S*\s+time:\s+\[\S+ \S+ (\S+) (\S+)", line)
        if m and last and "time:" + last not in thrpt:
            thrpt["time:" + last] = float(m.group(1)) * units[m.group(2)]
        m = re.match(r"^\s+thrpt:\s+\[\S+ \S+ (\S+) (\S+)", line)
        if m and last and last not in thrpt:
            thrpt[last] = float(m.group(1)) * rates[m.group(2)]
    return thrpt, tables


def fmt(x):
    """Three significant figures, as the guide's tables write them."""
    return f"{x:.3g}" if x < 100 else f"{x:.0f}"


def sampler():
    thrpt, _ = criterion("sampler")
    scales = [("magnified", "magnified (0.25 texel/px)"), ("1to1", "1:1"),
              ("minified3x", "3x minified"), ("minified4x", "4x minified"),
              ("minified64x", "64x minified")]
    filters = [("nearest", "nearest"), ("bilinear", "bilinear"),
               ("bicubic", "bicubic (Catmull-Rom)"), ("mip-nearest", "mip-nearest"),
               ("trilinear", "trilinear")]
    print("| filter | " + " | ".join(h for _, h in scales) + " |")
    print("|---|" + "--:|" * len(scales))
    for key, name in filters:
        cells = [f"{thrpt.get(f'sample/{s}/{key}', float('nan')):.1f}" for s, _ in scales]
        print(f"| {name} | " + " | ".join(cells) + " |")
    bounds = {k: v for k, v in thrpt.items() if k.startswith("bound/")}
    print()
    for k, v in sorted(bounds.items()):
        print(f"- `{k}`: {v:.1f} M samples/s")


def aniso():
    thrpt, tables = criterion("aniso")
    reads = {(t[1], t[3]): float(t[4]) for t in tables if t[0] == "texels_per_sample"}
    ratios = ["1", "4", "16", "64"]
    names = [("nearest", "nearest"), ("bilinear", "bilinear"), ("mip_nearest", "mip-nearest"),
             ("trilinear", "trilinear"), ("bicubic_trilinear", "bicubic trilinear"),
             ("aniso2", "anisotropic 2x"), ("aniso4", "anisotropic 4x"),
             ("aniso8", "anisotropic 8x"), ("aniso16", "anisotropic 16x"),
             ("ewa", "EWA (clamp 16)"), ("ripmap", "ripmap"), ("summed_area", "summed-area table")]
    print("| filter | " + " | ".join(f"ratio {r}" for r in ratios) + " |")
    print("|---|" + "---|" * len(ratios))
    for key, name in names:
        cells = []
        for r in ratios:
            t = thrpt.get(f"sample/{key}/ratio{r}", float("nan"))
            cells.append(f"{fmt(t)}, {reads.get((key, r), float('nan')):.1f}")
        print(f"| {name} | " + " | ".join(cells) + " |")
    size = {t[1]: int(t[2]) for t in tables if t[0] == "bytes"}
    print()
    print("| structure (2048 x 2048 RGBA8) | memory | build time |")
    print("|---|--:|--:|")
    for key, name, bench in [("pyramid", "mip pyramid (all levels)", "pyramid"),
                             ("ripmap", "ripmap (excluding level 0)", "ripmap"),
                             ("summed_area", "summed-area table (f64 x 4)", "summed_area")]:
        ms = thrpt.get(f"time:build2048/{bench}", float("nan"))
        print(f"| {name} | {size.get(key, 0):,} B | {ms:.0f} ms |")


def threads(scene):
    run(["cargo", "build", "--locked", "--release", "-p", "texel-cli"])
    texel = os.path.join(ROOT, "target", "release", "texel")
    medians = {}
    for n in (1, 2):
        out = run([texel, "bench", scene, "--frames", "10", "--threads", str(n), "--json",
                   "--filters", "nearest,bilinear,mip-nearest,trilinear,aniso16,ewa"])
        medians[n] = json.loads(out)["median_ms"]
    print("| render | 1 thread (ms) | 2 threads (ms) |")
    print("|---|--:|--:|")
    for f in medians[1]:
        print(f"| {f} | {medians[1][f]:.1f} | {medians[2][f]:.1f} |")


def demo():
    run(["cargo", "run", "--locked", "--release", "--", "demo"])
    report = open(os.path.join(ROOT, "texel-demo", "ground", "report.md")).read()
    rows = [line for line in report.splitlines() if line.startswith("|")]
    print("\n".join(rows[:14]))


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else ""
    if what == "sampler":
        sampler()
    elif what == "aniso":
        aniso()
    elif what == "threads":
        threads(sys.argv[2] if len(sys.argv) > 2 else "scenes/ground.toml")
    elif what == "demo":
        demo()
    else:
        sys.exit(__doc__)
