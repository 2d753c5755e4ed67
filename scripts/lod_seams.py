#!/usr/bin/env python3
"""How much a filter's result jumps where its level of detail crosses a level.

    target/python-venv/bin/python scripts/lod_seams.py

Samples a 256 x 256 uniform-noise texture (linear float, standard deviation 0.289 a channel,
Repeat) at 20 000 random points with footprints of ratio 4 at random angles, whose minor
semi-axis grows from 1.2 to 7 texels in 400 geometric steps (0.44 % apart). For each filter it
prints the RMS change (RGB) between consecutive steps: the median over the steps, and the three
largest with the minor semi-axis where they occur. A filter continuous in the footprint (trilinear,
the anisotropic filters) has no step far above its median; a filter that switches levels
(mip-nearest, EWA in its one level `floor(lod)`) jumps where its lod crosses an integer.
Needs the Python package (python/, built into target/python-venv by .ci/run) and numpy.
"""
import numpy as np

import texel

FILTERS = ["trilinear", "aniso16", "ewa", "mip-nearest"]


def main():
    rng = np.random.default_rng(7)
    n = 256
    img = rng.random((n, n, 4), dtype=np.float32)
    img[..., 3] = 1.0
    tex = texel.Texture(img, address="repeat")
    m = 20000
    uv = rng.random((m, 2)).astype(np.float32)
    angle = rng.random(m) * np.pi
    radii = np.exp(np.linspace(np.log(1.2), np.log(7.0), 400))
    major_dir = np.stack([np.cos(angle), np.sin(angle)], -1)
    minor_dir = np.stack([-np.sin(angle), np.cos(angle)], -1)

    def sample(r, f):
        dx = (major_dir * 4.0 * r / n).astype(np.float32)
        dy = (minor_dir * r / n).astype(np.float32)
        return tex.sample(uv, dx, dy, filter=f)[..., :3]

    print("| filter | median step (RMS) | three largest steps (RMS at minor semi-axis, texels) |")
    print("|---|--:|---|")
    for f in FILTERS:
        prev, steps = None, []
        for r in radii:
            s = sample(r, f)
            if prev is not None:
                steps.append(float(np.sqrt(np.mean((s - prev) ** 2))))
            prev = s
        steps = np.array(steps)
        mid = np.sqrt(radii[1:] * radii[:-1])
        top = np.argsort(steps)[-3:][::-1]
        largest = ", ".join(f"{steps[i]:.5f} at {mid[i]:.3f}" for i in top)
        print(f"| {f} | {np.median(steps):.5f} | {largest} |")


if __name__ == "__main__":
    main()
