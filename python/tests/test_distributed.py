"""texel.distributed on a local Ray with 2 CPUs equals the local calls bit for bit."""

import os

import numpy as np
import pytest

import texel
from conftest import write_png

try:
    import ray
except ImportError:
    ray = None
    if os.environ.get("CI") == "true":
        raise
    print("skipping texel.distributed tests: Ray is not installed (pip install ./python[ray])")

pytestmark = pytest.mark.skipif(ray is None, reason="Ray is not installed")


@pytest.fixture(scope="module")
def local_ray():
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


def test_render_jobs_equal_local_renders(local_ray, tmp_path):
    from texel import distributed

    # A scene file with a texture of its own beside it travels with it.
    rng = np.random.default_rng(5)
    write_png(tmp_path / "noise.png", (rng.random((32, 32, 3)) * 255).astype(np.uint8))
    scene = tmp_path / "plane.toml"
    scene.write_text(
        """
[output]
width = 48
height = 32
[camera]
eye = [0.0, 1.0, 0.0]
target = [0.0, 0.5, -5.0]
fovy_deg = 60.0
near = 0.05
far = 100.0
[textures.noise]
path = "noise.png"
[[meshes]]
texture = "noise"
positions = [[-20.0, 0.0, 1.0], [20.0, 0.0, 1.0], [20.0, 0.0, -40.0], [-20.0, 0.0, -40.0]]
uvs = [[-5.0, 0.0], [5.0, 0.0], [5.0, 10.0], [-5.0, 10.0]]
triangles = [[0, 1, 2], [0, 2, 3]]
"""
    )
    jobs = [
        {"scene": str(scene), "filter": "aniso16"},
        {"scene": "builtin:ground", "filter": "ewa", "size": (64, 36)},
        {"scene": str(scene), "filter": "trilinear", "color": "raw"},
    ]
    got = distributed.render(jobs)
    for job, image in zip(jobs, got):
        np.testing.assert_array_equal(image, texel.render(**job))


def test_bundles_carry_the_named_files(tmp_path):
    from texel import distributed

    (tmp_path / "tex").mkdir()
    (tmp_path / "tex" / "a.png").write_bytes(b"png")
    (tmp_path / "s.toml").write_text('[textures.a]\npath = "tex/a.png"\n')
    b = distributed.bundle(str(tmp_path / "s.toml"))
    assert b["path"] == "s.toml"
    assert b["files"] == {"s.toml": (tmp_path / "s.toml").read_bytes(), "tex/a.png": b"png"}
    assert distributed.bundle("builtin:ground") == {"scene": "builtin:ground"}


def test_tiled_reference_equals_the_local_reference(local_ray):
    from texel import distributed

    args = dict(spp=16, max_spp=64, size=(50, 30))
    local = texel.reference_estimate("builtin:ground", **args)
    tiled = distributed.reference_estimate("builtin:ground", tiles=(3, 2), **args)
    for key in ("image", "linear", "std_error", "spp", "converged"):
        np.testing.assert_array_equal(tiled[key], local[key], err_msg=key)
    np.testing.assert_array_equal(
        distributed.reference("builtin:ground", tiles=(2, 2), **args), local["image"]
    )


def test_bundles_ship_only_named_files_and_stay_in_their_directory(tmp_path):
    from texel import distributed

    (tmp_path / "secret.txt").write_bytes(b"secret")
    (tmp_path / "a.png").write_bytes(b"png")
    (tmp_path / "s.toml").write_text(
        'title = "secret.txt"\n[textures.a]\npath = "a.png"\n[environment]\nfaces = ["/etc/hostname"]\n'
    )
    b = distributed.bundle(tmp_path / "s.toml")
    assert sorted(b["files"]) == ["a.png", "s.toml"]
    work = tmp_path / "work"
    work.mkdir()
    for bad in ({"path": "s.toml", "files": {"../escaped.txt": b"x"}},
                {"path": "s.toml", "files": {str(tmp_path / "abs.txt"): b"y"}},
                {"path": "../s.toml", "files": {}}):
        with pytest.raises(ValueError, match="outside"):
            distributed._unpacked(bad, str(work))
    assert not (tmp_path / "escaped.txt").exists() and not (tmp_path / "abs.txt").exists()
