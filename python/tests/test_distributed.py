"""texel.distributed on a local Ray with 2 CPUs equals the local calls bit for bit."""

import os

import numpy as np
import pytest

import texel
from conftest import SCENE_HEAD, png_bytes, quad_mesh, solid_png, write_gltf, write_png

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


def _scene_of_many_files(tmp_path):
    """A scene naming its files every way TOML allows: a dotted key holding an inline table, a
    dotted key, a multi-line array (an environment cube map of six faces), a path outside the
    scene's directory, a glTF whose buffer and image are files of their own, and a GLB holding
    its image. Returns the scene's path and the bundle's expected files."""
    scene_dir = tmp_path / "scene"
    for d in ["tex", "env", "model/img"]:
        (scene_dir / d).mkdir(parents=True)
    (tmp_path / "common").mkdir()
    solid_png(scene_dir / "tex" / "a.png", (200, 10, 10))
    solid_png(tmp_path / "common" / "b.png", (10, 200, 10))
    faces = ["px", "nx", "py", "ny", "pz", "nz"]
    for k, face in enumerate(faces):
        solid_png(scene_dir / "env" / f"{face}.png", (20 * k, 40, 60))
    red = np.full((4, 4, 4), [255, 0, 0, 255], np.uint8)
    (scene_dir / "model" / "img" / "red.png").write_bytes(png_bytes(red))
    write_gltf(scene_dir / "model" / "quad.gltf", png_bytes(red), image_uri="img/red.png",
               buffer_uri="quad.bin")
    write_gltf(scene_dir / "model" / "blue.glb",
               png_bytes(np.full((4, 4, 4), [0, 0, 255, 255], np.uint8)), z=-0.5)
    # Files beside the scene that it does not read stay behind.
    (scene_dir / "notes.png").write_bytes(b"not read")
    (scene_dir / "tex" / "unused.png").write_bytes(png_bytes(red))
    face_lines = "".join(f'  "env/{f}.png",\n' for f in faces)
    text = (
        'textures.a = { path = "tex/a.png" }\n'
        'textures.b.path = "../common/b.png"\n'
        'textures.unused = { path = "tex/unused.png" }\n'
        + SCENE_HEAD
        + "[environment]\nfaces = [\n" + face_lines + "]\nbackground = true\n"
        + quad_mesh("a", z=-1.0).replace("[[meshes]]", "[[meshes]]\naddress_mode = 'clamp-to-edge'")
        + quad_mesh("b", z=-2.0)
        + '[[meshes]]\ngltf = "model/quad.gltf"\n'
        + '[[meshes]]\ngltf = "model/blue.glb"\n'
    )
    scene = scene_dir / "s.toml"
    scene.write_text(text)
    rel = ["scene/s.toml", "scene/tex/a.png", "common/b.png",
           *[f"scene/env/{f}.png" for f in faces],
           "scene/model/quad.gltf", "scene/model/quad.bin", "scene/model/img/red.png",
           "scene/model/blue.glb"]
    return scene, {r: (tmp_path / r).read_bytes() for r in rel}


def test_bundles_carry_every_file_the_loader_reads(tmp_path):
    from texel import distributed

    scene, expected = _scene_of_many_files(tmp_path)
    opened = {os.path.normpath(p) for p in texel.scene_files(scene)}
    assert opened == {str(tmp_path / r) for r in expected}
    b = distributed.bundle(str(scene))
    assert b["path"] == "scene/s.toml"
    assert b["files"] == expected
    assert distributed.bundle("builtin:ground") == {"scene": "builtin:ground"}
    assert texel.scene_files("builtin:ground") == []


def test_a_bundled_scene_renders_on_a_worker_as_here(local_ray, tmp_path):
    from texel import distributed

    scene, _ = _scene_of_many_files(tmp_path)
    local = texel.render(str(scene))
    # The worker reads the shipped copies: the originals are gone before it runs.
    b = distributed.bundle(scene)
    import shutil

    work = tmp_path / "elsewhere"
    shutil.move(str(tmp_path / "scene"), str(work / "scene"))
    shutil.move(str(tmp_path / "common"), str(work / "common"))
    got = ray.get(ray.remote(distributed._run_renders).remote([(0, {})], b))
    np.testing.assert_array_equal(got[0], local)


def test_many_jobs_share_tasks_in_order(local_ray):
    from texel import distributed

    assert distributed._batch_size(10**5, 2) == 12500
    assert distributed._batch_size(3, 2) == 1
    chunks = distributed._batches(10**5, 12500)
    assert len(chunks) == 8 and [k for c in chunks for k in c] == list(range(10**5))
    jobs = [
        {"scene": "builtin:ground", "size": (16 + k, 9), "filter": f}
        for k, f in enumerate(["nearest", "trilinear", "aniso4", "ewa", "sat"])
    ]
    text = ("[output]\nwidth = 8\nheight = 8\n" + SCENE_HEAD.split("\n", 3)[3]
            + '[textures.c]\nprocedural = "checker"\nsize = 16\n' + quad_mesh("c"))
    jobs.insert(2, {"scene": text})
    expected = [texel.render(**job) for job in jobs]
    for batch in (2, 4, None):
        got = distributed.render(jobs, batch=batch)
        assert len(got) == len(jobs)
        for e, g in zip(expected, got):
            np.testing.assert_array_equal(g, e)
    with pytest.raises(ValueError, match="batch"):
        distributed.render(jobs, batch=0)


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


def test_bundles_ship_only_relatively_named_files_and_stay_in_their_directory(tmp_path):
    from texel import distributed

    scene_dir = tmp_path / "scene"
    scene_dir.mkdir()
    (scene_dir / "secret.txt").write_bytes(b"secret")
    solid_png(scene_dir / "a.png", (1, 2, 3))
    (tmp_path / "elsewhere").mkdir()
    solid_png(tmp_path / "elsewhere" / "abs.png", (4, 5, 6))
    (scene_dir / "s.toml").write_text(
        "# secret.txt\n" + SCENE_HEAD
        + f'[textures.a]\npath = "a.png"\n[textures.abs]\npath = "{tmp_path / "elsewhere" / "abs.png"}"\n'
        + quad_mesh("a") + quad_mesh("abs", z=-1.0)
    )
    b = distributed.bundle(scene_dir / "s.toml")
    # A file named by absolute path is read where the task runs.
    assert sorted(b["files"]) == ["a.png", "s.toml"]
    work = tmp_path / "work"
    work.mkdir()
    for bad in ({"path": "s.toml", "files": {"../escaped.txt": b"x"}},
                {"path": "s.toml", "files": {str(tmp_path / "abs.txt"): b"y"}},
                {"path": "../s.toml", "files": {}}):
        with pytest.raises(ValueError, match="outside"):
            distributed._unpacked(bad, str(work))
    assert not (tmp_path / "escaped.txt").exists() and not (tmp_path / "abs.txt").exists()
