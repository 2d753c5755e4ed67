#!/usr/bin/env python3
"""Score reference images against a brute force: bias, error and calibration of the error bars.

  .venv-peers/bin/python scripts/reference_error.py BRUTE.exr FACTOR CANDIDATE.exr [...]
        [--errors A_ERR.exr B_ERR.exr]

BRUTE.exr is a `texel reference ... -o BRUTE.exr` at FACTOR times the candidates' width and height
(e.g. 640x360 for 160x90 with FACTOR 4); it is box-averaged FACTOR x FACTOR in linear light. Over
the plane (pixels the brute force does not show black) each candidate gets the mean absolute and
mean signed error of its displayed values (clipped, sRGB-encoded, in 8-bit steps). With --errors,
the last two candidates are one scene with two seeds (`--seed`, `--error-map X.exr`) and the two
error maps follow: it also prints the share of red values whose difference lies within 1.96
combined standard errors, and the share of the brute force within 1.96 and within 2.365 (t with 7
degrees of freedom, the minimum passes') of the first seed's standard errors. Needs numpy and OpenEXR (scripts/peers/setup.sh installs both).

The table in docs/guide/measuring.md ("The reference and its error bars"):
  texel reference scenes/glints.toml --size 640x360 --spp 4096 --max-spp 4096 -o bf.exr
  texel reference scenes/glints.toml --size 160x90 --spp 256 --max-spp 256 -o r256.exr
  texel reference scenes/glints.toml --size 160x90 --spp 4096 --max-spp 4096 -o r4096.exr
  texel reference scenes/glints.toml --size 160x90 --error-map e1.exr -o a1.exr
  texel reference scenes/glints.toml --size 160x90 --seed 2 --error-map e2.exr -o a2.exr
  .venv-peers/bin/python scripts/reference_error.py bf.exr 4 r256.exr r4096.exr a1.exr a2.exr \\
      --errors e1.exr e2.exr
"""
import sys

import numpy as np
import OpenEXR


def load(path):
    with OpenEXR.File(path) as f:
        ch = f.channels()
        if "RGBA" in ch:
            return ch["RGBA"].pixels.astype(np.float64)
        return np.stack([ch[c].pixels for c in "RGBA"], -1).astype(np.float64)


def display(x):
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055) * 255.0


def main():
    args = sys.argv[1:]
    errors = []
    if "--errors" in args:
        i = args.index("--errors")
        errors, args = args[i + 1:i + 3], args[:i]
    if len(args) < 3:
        sys.exit(__doc__)
    brute, k, candidates = args[0], int(args[1]), args[2:]
    bf = load(brute)
    h, w = bf.shape[0] // k, bf.shape[1] // k
    bf = bf[:h * k, :w * k].reshape(h, k, w, k, 4).mean(axis=(1, 3))
    truth = display(bf[..., :3])
    plane = truth.sum(-1) > 0
    print(f"plane: {plane.sum()} of {h * w} pixels")
    images = {}
    for c in candidates:
        img = load(c)
        images[c] = img
        d = display(img[..., :3]) - truth
        print(f"{c}: mean abs. error {np.abs(d[plane]).mean():.2f} steps, "
              f"mean signed {d[plane].mean():+.2f}")
    if len(errors) == 2 and len(candidates) >= 2:
        a, b = images[candidates[-2]][..., 0], images[candidates[-1]][..., 0]
        sa, sb = load(errors[0])[..., 0], load(errors[1])[..., 0]
        se = np.sqrt(sa ** 2 + sb ** 2)
        m = plane & (se > 0)
        within = (np.abs(a - b) <= 1.96 * se)[m].mean()
        print(f"two seeds within 1.96 combined standard errors: {within:.3f} of {m.sum()} pixels")
        # A pixel's interval is t(K - 1) standard errors, K its passes (8 or more): between the
        # normal 1.96 and the 8-pass 2.365.
        for t in (1.96, 2.365):
            covered = (np.abs(a - bf[..., 0]) <= t * sa)[plane].mean()
            print(f"brute force within {t} of the first seed's standard errors: {covered:.3f}")
    elif errors:
        sys.exit("--errors needs two error maps and at least two candidates")


if __name__ == "__main__":
    main()
