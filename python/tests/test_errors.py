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
