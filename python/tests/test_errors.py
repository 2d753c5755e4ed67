"""Bad input raises Python exceptions with texel's messages; nothing aborts the interpreter."""

import numpy as np
import pytest

import texel


def test_wrong_dtype_is_a_type_error():
    with pytest.raises(TypeError, match="uint8 or float32"):
        texel.Texture(np.zeros((4, 4, 3), dtype=np.int32))
    with pytest.raises(TypeError, match="float32 or float64"):
        texel.Texture(np.zeros((4, 4, 3), dtype=np.uint8)).sample(np.zeros((2, 2), dtype=np.int64))
    with pytest.raises(TypeError):
        texel.Texture([[1, 2], [3, 4]])


def test_wrong_shapes_are_value_errors():
    with pytest.raises(ValueError, match="channels"):
        texel.Texture(np.zeros((4, 4, 5), dtype=np.uint8))
    with pytest.raises(ValueError, match="shape"):
        texel.Texture(np.zeros((4,), dtype=np.uint8))
    with pytest.raises(ValueError, match="empty"):
        texel.Texture(np.zeros((0, 4, 3), dtype=np.uint8))
    t = texel.Texture(np.zeros((4, 4, 3), dtype=np.uint8))
    with pytest.raises(ValueError, match=r"\(\.\.\., 2\)"):
        t.sample(np.zeros((5, 3)), filter="nearest")
    with pytest.raises(ValueError, match="must match"):
        t.sample(np.zeros((5, 2)), np.zeros((4, 2)), np.zeros((5, 2)))


def test_shape_errors_say_what_the_shape_looks_like():
    with pytest.raises(ValueError, match=r"array has shape \(4, 64, 64\): it looks channels-first \(C, H, W\); texel takes \(H, W, C\)"):
        texel.Texture(np.zeros((4, 64, 64), np.uint8))
    with pytest.raises(ValueError, match=r"\(1, 8, 8, 3\): it looks like a batch of one image .* pass array\[0\]"):
        texel.Texture(np.zeros((1, 8, 8, 3), np.uint8))
    with pytest.raises(ValueError, match=r"linear has shape \(4, 64, 64\): it looks channels-first"):
        texel.encode(np.zeros((4, 64, 64), np.float32))
    with pytest.raises(ValueError, match=r"\(64, 64\): it looks like a grey \(H, W\) image.*linear\[\.\.\., None\]"):
        texel.encode(np.zeros((64, 64), np.float32))
    t = texel.Texture(np.zeros((4, 4, 3), dtype=np.uint8))
    with pytest.raises(ValueError, match=r"uv has shape \(2, 8, 8\): it looks channels-first \(2, \.\.\.\)"):
        t.sample(np.zeros((2, 8, 8)), filter="nearest")
    with pytest.raises(TypeError, match="float32"):
        texel.encode(np.zeros((4, 4), np.float64))


def test_nan_values_are_value_errors():
    t = texel.Texture(np.zeros((4, 4, 3), dtype=np.uint8))
    uv = np.zeros((3, 2))
    uv[1, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        t.sample(uv, filter="nearest")
    with pytest.raises(ValueError, match="NaN"):
        t.sample(np.zeros((1, 2)), np.array([[np.inf, 0]]), np.zeros((1, 2)))
    bad = np.zeros((2, 2, 4), dtype=np.float32)
    bad[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="finite|NaN"):
        texel.Texture(bad)
    # Finite but beyond the range whose filtered sums stay finite in float32.
    bad[0, 0, 0] = 3e38
    with pytest.raises(ValueError, match=r"texel \(0, 0\) channel R is 3e38: .*within"):
        texel.Texture(bad)
    with pytest.raises(ValueError, match="lod_bias"):
        t.sample(np.zeros((1, 2)), filter="bilinear", lod_bias=float("nan"))


def test_non_contiguous_arrays_are_refused():
    a = np.zeros((8, 8, 4), dtype=np.uint8)
    with pytest.raises(ValueError, match="contiguous"):
        texel.Texture(a[:, ::2])
    t = texel.Texture(a)
    with pytest.raises(ValueError, match="contiguous"):
        t.sample(np.zeros((2, 4))[:, ::2], filter="nearest")


def test_names_and_missing_footprints():
    t = texel.Texture(np.zeros((4, 4, 3), dtype=np.uint8))
    with pytest.raises(ValueError, match="unknown filter"):
        t.sample(np.zeros((1, 2)), filter="gaussian")
    with pytest.raises(ValueError, match="duv_dx"):
        t.sample(np.zeros((1, 2)), filter="trilinear")
    with pytest.raises(ValueError, match="address mode"):
        texel.Texture(np.zeros((4, 4, 3), dtype=np.uint8), address="wrap")
    with pytest.raises(ValueError, match="unknown view"):
        texel.render("builtin:ground", size=(8, 8), view="depthish")


def test_files_memory_and_malformed_scenes():
    with pytest.raises(OSError, match="no-such-scene.toml"):
        texel.render("no-such-scene.toml")
    with pytest.raises(MemoryError, match="needs about"):
        texel.render("builtin:ground", size=(64, 36), max_memory=1000)
    with pytest.raises(ValueError, match=r"<scene text>:2:9: invalid type"):
        texel.render("[output]\nwidth = 'wide'\n")
    with pytest.raises(ValueError, match="size"):
        texel.render("builtin:ground", size=(0, 4))
    with pytest.raises(ValueError, match="max_spp"):
        texel.reference("builtin:ground", spp=64, max_spp=16, size=(8, 8))
    with pytest.raises(ValueError):
        texel.warp(np.zeros((4, 4, 3), dtype=np.uint8), [0, 0, 1, 1])


def test_fortran_order_and_misaligned_arrays_are_refused():
    a = np.arange(16, dtype=np.float32).reshape(4, 4)
    with pytest.raises(ValueError, match="C-contiguous"):
        texel.Texture(np.asfortranarray(a[:, :3]))
    t = texel.Texture(a)
    uv = np.array([[0.125, 0.125], [0.875, 0.125], [0.125, 0.875]])
    with pytest.raises(ValueError, match="C-contiguous"):
        t.sample(np.asfortranarray(uv), filter="nearest")
    odd = np.frombuffer(bytearray(257), np.float32, offset=1, count=64).reshape(4, 4, 4)
    with pytest.raises(ValueError, match="aligned"):
        texel.Texture(odd)
    odd_uv = np.frombuffer(bytearray(8 * 6 + 1), np.float64, offset=1, count=6).reshape(3, 2)
    with pytest.raises(ValueError, match="aligned"):
        t.sample(odd_uv, filter="nearest")


def test_sizes_are_checked_before_copying():
    # A 1 x 2^30 view costs nothing; the texture limit refuses it before texels are widened.
    wide = np.lib.stride_tricks.as_strided(np.zeros(1, np.uint8), shape=(1, 2**30), strides=(0, 0))
    with pytest.raises(ValueError, match="cannot be a texture"):
        texel.Texture(np.ascontiguousarray(wide[:, :20000]))


def test_threads_and_tolerance_are_checked():
    with pytest.raises(ValueError, match="threads must be 1 to 1024"):
        texel.render("builtin:ground", size=(8, 8), threads=5000)
    with pytest.raises(ValueError, match="threads must be"):
        texel.render("builtin:ground", size=(8, 8), threads=0)
    with pytest.raises(ValueError, match="tolerance must be"):
        texel.reference("builtin:ground", size=(8, 8), spp=4, max_spp=4, tolerance=-1)


def test_friendly_spellings():
    import pathlib

    from conftest import ROOT

    img = np.zeros((8, 8, 4), dtype=np.uint8)
    flat = texel.warp(img, [0, 0, 8, 0, 8, 8, 0, 8], size=(4, 4), filter="bilinear")
    pairs = texel.warp(img, [(0, 0), (8, 0), (8, 8), (0, 8)], size=(4, 4), filter="bilinear")
    np.testing.assert_array_equal(flat, pairs)
    path = pathlib.Path(ROOT / "scenes" / "ground.toml")
    np.testing.assert_array_equal(
        texel.render(path, size=(16, 9)), texel.render(str(path), size=(16, 9))
    )
    assert "glossy" in texel.BUILTIN_SCENES and "ground" in texel.BUILTIN_SCENES
    got = texel.compare("builtin:ground", filters=["all"], spp=4, size=(48, 27))
    assert list(got) == texel.FILTERS


def test_ctrl_c_stops_a_reference_with_keyboard_interrupt():
    import signal
    import subprocess
    import sys
    import time

    code = (
        "import texel\n"
        "print('started', flush=True)\n"
        "try:\n"
        "    texel.reference('builtin:glossy', size=(320, 180), spp=256, max_spp=65536)\n"
        "    print('finished')\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted')\n"
    )
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "started"
    time.sleep(1.0)
    p.send_signal(signal.SIGINT)
    out, _ = p.communicate(timeout=300)
    assert p.returncode == 0 and out.strip() == "interrupted", out
