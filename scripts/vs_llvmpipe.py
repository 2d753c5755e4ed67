#!/usr/bin/env python3
"""texel vs Mesa's llvmpipe on the same scene, same machine, same run.

Alternates `texel bench --json` and `scripts/peers/llvmpipe_bench.py` for a few rounds (the
machine is shared and noisy: alternating keeps both under the same conditions) and prints a
Markdown table of the medians of each round's medians, the texel / llvmpipe ratio per round, and
texel's aniso16 and EWA frames as multiples of its own trilinear frame.

Run from the repository root after `cargo build --release` and `scripts/peers/setup.sh`:

    .venv-peers/bin/python scripts/vs_llvmpipe.py [--rounds 3] [--frames 10] [--threads 2]

texel runs with `--color raw` (texture bytes are linear, as a GPU samples a plain RGBA8 texture),
which is what llvmpipe does with the scene's textures. llvmpipe's 16x anisotropic filter (an EWA
port in Mesa 22.3) takes seconds per frame; `--llvmpipe-aniso` times one frame of it once.
`--gpu-precision` also times texel's four core filters with `--precision gpu` (8-bit fixed-point
weights, as llvmpipe blends) in every round and adds its columns; `--float-storage` does the same
with `--texture-storage float` (textures decoded once to `f32`: the same images, four times the
texture memory).
"""

import argparse
import json
import statistics
import subprocess
import sys

CORE = ["nearest", "bilinear", "mip-nearest", "trilinear"]
TEXEL_ONLY = ["aniso16", "ewa"]


def run_json(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scene", default="scenes/ground.toml")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--frames", type=int, default=10)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--texel", default="target/release/texel")
    ap.add_argument("--peer", default="scripts/peers/llvmpipe_bench.py")
    ap.add_argument("--llvmpipe-aniso", action="store_true",
                    help="also time one llvmpipe aniso16 frame (tens of seconds)")
    ap.add_argument("--gpu-precision", action="store_true",
                    help="also time texel's core filters with --precision gpu")
    ap.add_argument("--float-storage", action="store_true",
                    help="also time texel's core filters with --texture-storage float")
    a = ap.parse_args()

    def bench(filters, *extra):
        """One `texel bench --json` of `filters` with `extra` options: ms per frame by filter."""
        return run_json([a.texel, "bench", a.scene, "--color", "raw", "--frames", str(a.frames),
                         "--threads", str(a.threads), "--filters", ",".join(filters), *extra,
                         "--json"])["median_ms"]

    texel, peer, fixed, floats = [], [], [], []
    renderer = "llvmpipe"
    for r in range(a.rounds):
        print(f"round {r + 1}/{a.rounds}", file=sys.stderr)
        texel.append(bench(CORE + TEXEL_ONLY))
        if a.gpu_precision:
            fixed.append(bench(CORE, "--precision", "gpu"))
        if a.float_storage:
            floats.append(bench(CORE + TEXEL_ONLY, "--texture-storage", "float"))
        p = run_json([sys.executable, a.peer, a.scene, "--frames", str(a.frames), "--threads",
                      str(a.threads), "--filters", ",".join(CORE)])
        renderer = f"{p.get('renderer', 'llvmpipe')}, {p.get('version', '')}"
        peer.append(p["median_ms"])
    aniso_peer = None
    if a.llvmpipe_aniso:
        aniso_peer = run_json([sys.executable, a.peer, a.scene, "--frames", "1", "--threads",
                               str(a.threads), "--filters", "aniso16"])["median_ms"]["aniso16"]

    print(f"{renderer}; {a.rounds} alternating rounds, {a.frames} frames each, "
          f"{a.threads} threads; ms per frame (median of the rounds' medians)\n")
    extras = [(name, runs) for name, runs in [("gpu precision", fixed), ("float storage", floats)]
              if runs]
    extra_head = "".join(f" texel {n} | {n} / llvmpipe (per round) |" for n, _ in extras)
    print(f"| filter | texel | llvmpipe | texel / llvmpipe (per round) |{extra_head}")
    print("|---|--:|--:|--:|" + "--:|--:|" * len(extras))

    def ratio_cells(t, p):
        ratios = [x / y for x, y in zip(t, p)]
        per_round = ", ".join(f"{x:.2f}" for x in ratios)
        return f"{statistics.median(t):.2f} | ", f"{statistics.median(ratios):.2f} ({per_round}) |"

    for f in CORE:
        p = [x[f] for x in peer]
        t, r = ratio_cells([x[f] for x in texel], p)
        extra = ""
        for _, runs in extras:
            g, gr = ratio_cells([x[f] for x in runs], p)
            extra += f" {g}{gr}"
        print(f"| {f} | {t}{statistics.median(p):.2f} | {r}{extra}")
    for f in TEXEL_ONLY:
        t = statistics.median(x[f] for x in texel)
        other = f"{aniso_peer:.0f} (one frame)" if f == "aniso16" and aniso_peer else "-"
        ratio = f"{t / aniso_peer:.4f}" if f == "aniso16" and aniso_peer else "-"
        cells = "".join(f" {statistics.median(x[f] for x in runs):.2f} | - |" if f in runs[0]
                        else " | |" for _, runs in extras)
        print(f"| {f} | {t:.2f} | {other} | {ratio} |" + cells)
    for f in TEXEL_ONLY:
        per_round = ", ".join(f"{x[f] / x['trilinear']:.1f}" for x in texel)
        print(f"\ntexel {f} / texel trilinear per round: {per_round}")
        if floats:
            per_round = ", ".join(f"{x[f] / x['trilinear']:.1f}" for x in floats)
            print(f"texel {f} / texel trilinear per round, float storage: {per_round}")


if __name__ == "__main__":
    main()
