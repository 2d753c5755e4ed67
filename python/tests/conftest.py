"""Shared helpers: the texel command (built by `cargo build --release`) and PNG reading."""

import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def texel_bin():
    """The texel binary: $TEXEL_BIN, else the workspace's release build."""
    path = os.environ.get("TEXEL_BIN") or str(ROOT / "target" / "release" / "texel")
    return path if os.path.isfile(path) and os.access(path, os.X_OK) else None


@pytest.fixture(scope="module")
def cli():
    """Run the texel command; tests that compare with it need it built."""
    path = texel_bin()
    if path is None:
        if os.environ.get("CI") == "true":
            pytest.fail("target/release/texel is missing: cargo build --release first")
        pytest.skip("target/release/texel is not built (cargo build --release)")

    def run(*args, cwd=None):
        done = subprocess.run([path, *map(str, args)], cwd=cwd, capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        return done

    return run


def read_png(path):
    """An 8-bit RGBA PNG as an H x W x 4 uint8 array."""
    from PIL import Image

    with Image.open(path) as im:
        assert im.mode == "RGBA", im.mode
        return np.asarray(im).copy()


def write_png(path, array):
    from PIL import Image

    Image.fromarray(array).save(path)
