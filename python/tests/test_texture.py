"""Texture and sampling: exact formulas, invariants, and every filter against the CLI's warp."""

import numpy as np
import pytest

import texel
from conftest import read_png, write_png


def test_levels_are_box_means_down_to_one_texel():
    rng = np.random.default_rng(1)
    a = rng.random((8, 16, 4), dtype=np.float32)
    t = texel.Texture(a)
    levels = t.levels()
    assert [l.shape for l in levels] == [(8, 16, 4), (4, 8, 4), (2, 4, 4), (1, 2, 4), (1, 1, 4)]
    assert t.dtype == "float32" and (t.width, t.height) == (16, 8)
    np.testing.assert_array_equal(levels[0], a)
    # Each level is the 2 x 2 box mean of the one above (float: exact to rounding).
    for above, below in zip(levels, levels[1:]):
        h, w = below.shape[:2]
        if above.shape[:2] == (2 * h, 2 * w):
            box = above.reshape(h, 2, w, 2, 4).mean(axis=(1, 3))
            np.testing.assert_allclose(below, box, rtol=1e-6, atol=1e-7)


def test_channels_widen_to_rgba():
    grey = np.array([[10, 200]], dtype=np.uint8)
    t = texel.Texture(grey, color="linear")
    np.testing.assert_array_equal(t.levels()[0][0], [[10, 10, 10, 255], [200, 200, 200, 255]])
    ga = np.array([[[10, 7]]], dtype=np.uint8)
    np.testing.assert_array_equal(texel.Texture(ga).levels()[0][0, 0], [10, 10, 10, 7])
    rgb = np.array([[[1.0, 0.5, 0.25]]], dtype=np.float32)
    np.testing.assert_array_equal(texel.Texture(rgb).levels()[0][0, 0], [1.0, 0.5, 0.25, 1.0])


def test_nearest_reads_the_texel_under_the_point():
    rng = np.random.default_rng(2)
    a = rng.random((4, 8, 4), dtype=np.float32)
    t = texel.Texture(a, address="clamp")
    j, i = np.mgrid[0:4, 0:8]
    uv = np.stack([(i + 0.5) / 8, (j + 0.5) / 4], axis=-1)
    out = t.sample(uv, filter="nearest")
    assert out.shape == (4, 8, 4) and out.dtype == np.float32
    np.testing.assert_array_equal(out, a)


def test_bilinear_halfway_is_the_mean_and_8bit_srgb_decodes():
    a = np.array([[[0.0, 0.0, 0.0, 1.0], [1.0, 0.5, 0.25, 1.0]]], dtype=np.float32)
    t = texel.Texture(a, address="clamp")
    out = t.sample(np.array([0.5, 0.5]), filter="bilinear")
    np.testing.assert_allclose(out, [0.5, 0.25, 0.125, 1.0], rtol=1e-6)
    # sRGB 8-bit 188 decodes to about 0.5029 linear.
    t8 = texel.Texture(np.full((1, 1, 3), 188, dtype=np.uint8))
    v = t8.sample(np.array([[0.5, 0.5]]), filter="nearest")[0, 0]
    expected = ((188 / 255 + 0.055) / 1.055) ** 2.4
    assert abs(v - expected) < 1e-4


def test_repeat_and_mirror_address_modes():
    a = np.arange(4, dtype=np.float32).reshape(1, 4, 1)
    uv = np.array([[1.125, 0.5], [-0.125, 0.5]])
    rep = texel.Texture(a, address="repeat").sample(uv, filter="nearest")[:, 0]
    mir = texel.Texture(a, address="mirror").sample(uv, filter="nearest")[:, 0]
    np.testing.assert_array_equal(rep, [0.0, 3.0])
    np.testing.assert_array_equal(mir, [3.0, 0.0])


def test_a_constant_texture_filters_to_itself_with_every_filter():
    t = texel.Texture(np.full((32, 32, 4), 0.375, dtype=np.float32))
    rng = np.random.default_rng(3)
    uv = rng.random((100, 2))
    dx = rng.normal(scale=0.05, size=(100, 2))
    dy = rng.normal(scale=0.05, size=(100, 2))
    for f in texel.FILTERS:
        out = t.sample(uv, dx, dy, filter=f)
        np.testing.assert_allclose(out, 0.375, atol=2e-6, err_msg=f)


def test_lod_bias_selects_coarser_levels():
    # A 2x2 checker: level 0 alternates, level 1 is its mean.
    a = np.array([[[0.0] * 3 + [1.0], [1.0] * 4], [[1.0] * 4, [0.0] * 3 + [1.0]]], dtype=np.float32)
    t = texel.Texture(a)
    uv = np.array([[0.25, 0.25]])
    # One texel per pixel: lod 0; a bias of 1 reads level 1.
    dx, dy = np.array([[0.5, 0.0]]), np.array([[0.0, 0.5]])
    assert t.sample(uv, dx, dy, filter="mip-nearest")[0, 0] == 0.0
    assert t.sample(uv, dx, dy, filter="mip-nearest", lod_bias=1.0)[0, 0] == 0.5


@pytest.mark.parametrize("name", texel.FILTERS)
def test_every_filter_matches_the_cli_warp(cli, tmp_path, name):
    """A warp that shrinks 2x across and 4x down has per-pixel footprint (1/w, 0), (0, 1/h): the
    same footprints through Texture.sample give the command's image."""
    rng = np.random.default_rng(4)
    src = (rng.random((64, 64, 4)) * 255).astype(np.uint8)
    src[..., 3] = 255
    write_png(tmp_path / "src.png", src)
    w, h = 32, 16
    cli(
        "warp", tmp_path / "src.png", "--corners", "0,0,64,0,64,64,0,64",
        "--size", f"{w}x{h}", "--filter", name, "-o", tmp_path / "out.png",
    )
    expected = read_png(tmp_path / "out.png")
    j, i = np.mgrid[0:h, 0:w]
    uv = np.stack([(i + 0.5) / w, (j + 0.5) / h], axis=-1)
    dx = np.broadcast_to(np.array([1 / w, 0.0]), uv.shape).copy()
    dy = np.broadcast_to(np.array([0.0, 1 / h]), uv.shape).copy()
    t = texel.Texture(src, address="clamp-to-border")
    got = texel.encode(t.sample(uv, dx, dy, filter=name))
    np.testing.assert_array_equal(got, expected)
    # texel.warp itself gives the same image.
    np.testing.assert_array_equal(
        texel.warp(src, [0, 0, 64, 0, 64, 64, 0, 64], size=(w, h), filter=name), expected
    )
