#!/usr/bin/env python3
"""texel vs Mesa's llvmpipe on the same scene, same machine, same run (issue 6).

Alternates `texel bench --json` and `../shared/peers/llvmpipe_bench.py` for a few rounds (the
machine is shared and noisy: alternating keeps both under the same conditions) and prints a
Markdown table of the medians of each round's medians, the texel / llvmpipe ratio per round, and
texel's aniso16 and EWA frames as multiples of its own trilinear frame.

Run from the repository root after `cargo build --release` and the peer set-up of
`../shared/peers/README.md`:

    ../peers-venv/bin/python scripts/vs_llvmpipe.py [--rounds 3] [--frames 10] [--threads 2]

texel runs with `--color raw` (texture bytes are linear, as a GPU samples a plain RGBA8 texture),
which is what llvmpipe does with the scene's textures. llvmpipe's 16x anisotropic filter (an EWA
port in Mesa 22.3) takes seconds per frame; `--llvmpipe-aniso` times one frame of it once.
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
    ap.add_argument("--scene", default="../shared/scenes/ground.toml")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--frames", type=int, default=10)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--texel", default="target/release/texel")
    ap.add_argument("--peer", default="../shared/peers/llvmpipe_bench.py")
    ap.add_argument("--llvmpipe-aniso", action="store_true",
                    help="also time one llvmpipe aniso16 frame (tens of seconds)")
    a = ap.parse_args()

    texel, peer = [], []
    renderer = "llvmpipe"
    for r in range(a.rounds):
        print(f"round {r + 1}/{a.rounds}", file=sys.stderr)
        texel.append(run_json([a.texel, "bench", a.scene, "--color", "raw", "--frames",
                               str(a.frames), "--threads", str(a.threads), "--filters",
                               ",".join(CORE + TEXEL_ONLY), "--json"])["median_ms"])
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
    print("| filter | texel | llvmpipe | texel / llvmpipe (per round) |")
    print("|---|--:|--:|--:|")
    for f in CORE:
        t = [x[f] for x in texel]
        p = [x[f] for x in peer]
        ratios = [x / y for x, y in zip(t, p)]
        per_round = ", ".join(f"{x:.2f}" for x in ratios)
        print(f"| {f} | {statistics.median(t):.2f} | {statistics.median(p):.2f} | "
              f"{statistics.median(ratios):.2f} ({per_round}) |")
    for f in TEXEL_ONLY:
        t = statistics.median(x[f] for x in texel)
        other = f"{aniso_peer:.0f} (one frame)" if f == "aniso16" and aniso_peer else "-"
        ratio = f"{t / aniso_peer:.4f}" if f == "aniso16" and aniso_peer else "-"
        print(f"| {f} | {t:.2f} | {other} | {ratio} |")
    for f in TEXEL_ONLY:
        per_round = ", ".join(f"{x[f] / x['trilinear']:.1f}" for x in texel)
        print(f"\ntexel {f} / texel trilinear per round: {per_round}")


if __name__ == "__main__":
    main()
