"""Texture and sampling: exact formulas, invariants, and every filter against the CLI's warp."""

import numpy as np
import pytest

import texel
from conftest import read_png, write_png


def test_levels_are_box_means_down_to_one_texel():
    """Even sides: each level is the 2 x 2 box mean of the one above."""
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
    t8 = texel.Texture(np.full((1, 1, 3), 188, dtype=np.uint8), color="srgb")
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


@pytest.mark.parametrize("color", ["srgb", "raw"])
@pytest.mark.parametrize("name", texel.FILTERS)
def test_every_filter_matches_the_cli_warp(cli, tmp_path, name, color):
    """A warp that shrinks 2x across and 4x down has per-pixel footprint (1/w, 0), (0, 1/h): the
    same footprints through Texture.sample give the command's image, in either colour handling."""
    rng = np.random.default_rng(4)
    src = (rng.random((64, 64, 4)) * 255).astype(np.uint8)
    src[..., 3] = 255
    write_png(tmp_path / "src.png", src)
    w, h = 32, 16
    cli(
        "warp", tmp_path / "src.png", "--corners", "0,0,64,0,64,64,0,64",
        "--size", f"{w}x{h}", "--filter", name, "--color", color, "-o", tmp_path / "out.png",
    )
    expected = read_png(tmp_path / "out.png")
    j, i = np.mgrid[0:h, 0:w]
    uv = np.stack([(i + 0.5) / w, (j + 0.5) / h], axis=-1)
    dx = np.broadcast_to(np.array([1 / w, 0.0]), uv.shape).copy()
    dy = np.broadcast_to(np.array([0.0, 1 / h]), uv.shape).copy()
    t = texel.Texture(src, color=color, address="clamp-to-border")
    got = texel.encode(t.sample(uv, dx, dy, filter=name), color=color)
    np.testing.assert_array_equal(got, expected)
    # texel.warp itself gives the same image; its default reads the codes as stored (raw).
    corners = [0, 0, 64, 0, 64, 64, 0, 64]
    np.testing.assert_array_equal(
        texel.warp(src, corners, size=(w, h), filter=name, color=color), expected
    )
    if color == "raw":
        np.testing.assert_array_equal(texel.warp(src, corners, size=(w, h), filter=name), expected)


def _box_taps(n):
    """The exact box reduction of an axis of n texels to max(1, n // 2): row k weighs each source
    texel by its overlap with [k n / m, (k + 1) n / m), divided by n / m."""
    m = max(1, n // 2)
    taps = np.zeros((m, n))
    for k in range(m):
        lo, hi = k * n / m, (k + 1) * n / m
        for i in range(n):
            taps[k, i] = max(0.0, min(hi, i + 1) - max(lo, i)) / (n / m)
    return taps


def test_odd_levels_weigh_the_texels_they_cover_and_keep_the_mean():
    rng = np.random.default_rng(11)
    a = rng.random((3, 5, 4), dtype=np.float32)
    levels = texel.Texture(a).levels()
    assert [l.shape for l in levels] == [(3, 5, 4), (1, 2, 4), (1, 1, 4)]
    np.testing.assert_allclose(_box_taps(5), [[0.4, 0.4, 0.2, 0, 0], [0, 0, 0.2, 0.4, 0.4]])
    for above, below in zip(levels, levels[1:]):
        h, w = above.shape[:2]
        box = np.einsum("yj,jic,xi->yxc", _box_taps(h), above.astype(np.float64), _box_taps(w))
        np.testing.assert_allclose(below, box, rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(levels[-1][0, 0], a.mean(axis=(0, 1)), rtol=1e-6)


def _centres(h, w):
    j, i = np.mgrid[0:h, 0:w]
    return np.stack([(i + 0.5) / w, (j + 0.5) / h], axis=-1)


def test_uint8_is_read_as_stored_by_default_and_srgb_on_request():
    codes = np.arange(256, dtype=np.uint8).reshape(16, 16)
    uv = _centres(16, 16)
    raw = texel.Texture(codes).sample(uv, filter="nearest")
    # As OpenCV's remap, scipy's map_coordinates and torch's grid_sample read a uint8 image.
    np.testing.assert_array_equal(raw[..., 0], codes.astype(np.float32) / np.float32(255))
    np.testing.assert_array_equal(texel.encode(raw)[..., 0], codes)
    srgb = texel.Texture(codes, color="srgb").sample(uv, filter="nearest")
    expected = np.where(codes / 255 <= 0.04045, codes / 255 / 12.92, ((codes / 255 + 0.055) / 1.055) ** 2.4)
    np.testing.assert_allclose(srgb[..., 0], expected, atol=1e-6)
    # Each encoding inverts its decoding exactly.
    np.testing.assert_array_equal(texel.encode(srgb, color="srgb")[..., 0], codes)
    assert texel.Texture(codes).color == "linear" and texel.Texture(codes, color="raw").color == "linear"


def _quad_differences(a, axis):
    """The derivative a GPU's 2 x 2 quads take along ``axis``: within each pair (2m, 2m + 1), the
    odd point minus the even one for both; the last point of an odd axis, backward."""
    n = a.shape[axis]
    if n < 2:
        return np.zeros_like(a)
    k = np.arange(n)
    lo, hi = k & ~1, (k & ~1) + 1
    last = hi >= n
    lo[last], hi[last] = k[last] - 1, k[last]
    return np.take(a, hi, axis=axis) - np.take(a, lo, axis=axis)


def test_a_grid_derives_its_footprint_from_its_quads():
    rng = np.random.default_rng(12)
    t = texel.Texture(rng.random((64, 64, 4), dtype=np.float32))
    # A perspective grid of odd sides: the footprint changes from pixel to pixel.
    j, i = np.mgrid[0:9, 0:7]
    w = 1.0 + 0.3 * j
    uv = np.stack([(i * 0.9 + 0.5) / (7 * w), (j * 1.7 + 0.5) / (9 * w)], axis=-1).astype(np.float32)
    dx, dy = _quad_differences(uv, 1), _quad_differences(uv, 0)
    assert len(np.unique(dx[..., 0])) > 4 and len(np.unique(dy[..., 1])) > 4
    for f in ["mip-nearest", "trilinear", "aniso16", "ewa", "ripmap", "sat"]:
        np.testing.assert_array_equal(t.sample(uv, filter=f), t.sample(uv, dx, dy, filter=f), err_msg=f)
    # A batch of grids: each grid's own neighbours, none across grids.
    flipped = np.ascontiguousarray(uv[::-1])
    both = t.sample(np.stack([uv, flipped]))
    np.testing.assert_array_equal(both[0], t.sample(uv))
    np.testing.assert_array_equal(both[1], t.sample(flipped))
    # An affine grid's differences are its constant step, up to rounding.
    grid = _centres(16, 32)
    step = t.sample(grid, np.full(grid.shape, [1 / 32, 0]), np.full(grid.shape, [0, 1 / 16]))
    np.testing.assert_allclose(t.sample(grid), step, atol=1e-5)
    with pytest.raises(ValueError, match=r"grid whose neighbours give them \(uv has shape \(5, 2\)\)"):
        t.sample(np.zeros((5, 2)))
    with pytest.raises(ValueError, match="both duv_dx and duv_dy, or neither"):
        t.sample(uv, duv_dx=dx)


def test_pixel_coordinates_give_the_samples_of_uv():
    rng = np.random.default_rng(13)
    a = rng.random((32, 64, 4), dtype=np.float32)
    t = texel.Texture(a, address="mirror")
    uv = rng.random((200, 2)) * 1.5 - 0.25
    dx = rng.normal(scale=0.02, size=(200, 2))
    dy = rng.normal(scale=0.02, size=(200, 2))
    size = np.array([64, 32])
    for f in texel.FILTERS:
        np.testing.assert_array_equal(
            t.sample(uv * size, dx * size, dy * size, filter=f, coords="pixels"),
            t.sample(uv, dx, dy, filter=f),
            err_msg=f,
        )
    grid = _centres(8, 16)
    np.testing.assert_array_equal(t.sample(grid * size, coords="pixels"), t.sample(grid))
    # Texel centres sit at +0.5: pixel (i + 0.5, j + 0.5) is texel (i, j).
    j, i = np.mgrid[0:32, 0:64]
    np.testing.assert_array_equal(t.sample(np.stack([i + 0.5, j + 0.5], -1), filter="nearest", coords="pixels"), a)
    # An OpenCV remap map (centres at integers) is the pixel coordinate less 0.5.
    x, y = 10.25, 7.75
    x0, y0, fx, fy = int(x), int(y), x - int(x), y - int(y)
    manual = (a[y0, x0] * (1 - fx) * (1 - fy) + a[y0, x0 + 1] * fx * (1 - fy)
              + a[y0 + 1, x0] * (1 - fx) * fy + a[y0 + 1, x0 + 1] * fx * fy)
    got = t.sample(np.array([[x + 0.5, y + 0.5]]), filter="bilinear", coords="pixels")[0]
    np.testing.assert_allclose(got, manual, rtol=1e-5)
    with pytest.raises(ValueError, match="unknown coords"):
        t.sample(uv, filter="nearest", coords="texels")


def test_encode_reads_the_last_axis_as_channels():
    rng = np.random.default_rng(14)
    samples = rng.random((10, 4), dtype=np.float32)
    got = texel.encode(samples)
    assert got.shape == (10, 4) and got.dtype == np.uint8
    np.testing.assert_array_equal(got, np.round(samples * 255).astype(np.uint8))
    image = samples.reshape(2, 5, 4)
    np.testing.assert_array_equal(texel.encode(image), got.reshape(2, 5, 4))
    rgb = samples[:, :3].copy()
    np.testing.assert_array_equal(texel.encode(rgb)[:, :3], got[:, :3])
    assert np.all(texel.encode(rgb)[:, 3] == 255)
    np.testing.assert_array_equal(texel.encode(samples, color="srgb")[:, 3], got[:, 3])


def test_textures_pickle_with_their_texels_and_options():
    import copy
    import pickle

    rng = np.random.default_rng(15)
    codes = (rng.random((12, 20, 4)) * 255).astype(np.uint8)
    t = texel.Texture(codes, color="srgb", address_u="clamp-to-border", address_v="mirror",
                      border="opaque-white")
    back = pickle.loads(pickle.dumps(t))
    assert (back.color, back.address_u, back.address_v, back.border) == (
        "srgb", "clamp-to-border", "mirror-repeat", "opaque-white")
    assert repr(back) == repr(t)
    for a, b in zip(t.levels(), back.levels()):
        np.testing.assert_array_equal(a, b)
    uv = rng.random((50, 2)) * 1.4 - 0.2
    d = np.full((50, 2), 0.05)
    for f in texel.FILTERS:
        np.testing.assert_array_equal(back.sample(uv, d, d, filter=f), t.sample(uv, d, d, filter=f))
    f32 = texel.Texture(rng.random((4, 4, 4), dtype=np.float32), color="srgb", address="clamp")
    assert f32.color == "linear"
    np.testing.assert_array_equal(copy.deepcopy(f32).levels()[0], f32.levels()[0])


def test_thread_counts_give_the_same_samples():
    rng = np.random.default_rng(16)
    t = texel.Texture(rng.random((64, 64, 4), dtype=np.float32))
    uv = rng.random((20000, 2))
    d = np.full((20000, 2), 0.01)
    one = t.sample(uv, d, d, filter="aniso8", threads=1)
    np.testing.assert_array_equal(t.sample(uv, d, d, filter="aniso8", threads=3), one)
    np.testing.assert_array_equal(t.sample(uv, d, d, filter="aniso8"), one)
    with pytest.raises(ValueError, match="threads must be 1 to 1024"):
        t.sample(uv, d, d, threads=0)
