"""render, reference and compare give what the texel command writes."""

import json
import pathlib

import numpy as np
import pytest

import texel
from conftest import ROOT, SCENE_HEAD, png_bytes, quad_mesh, read_png, solid_png, write_gltf, write_obj


@pytest.mark.parametrize(
    "filter,color,view",
    [("trilinear", "srgb", "color"), ("aniso16", "raw", "color"), ("ewa", "srgb", "color"),
     ("trilinear", "raw", "mip")],
)
def test_render_equals_the_cli_png(cli, tmp_path, filter, color, view):
    out = tmp_path / "cli.png"
    cli("render", "builtin:ground", "--size", "96x54", "--filter", filter, "--color", color,
        "--view", view, "-o", out)
    got = texel.render("builtin:ground", filter=filter, size=(96, 54), color=color, view=view)
    assert got.shape == (54, 96, 4) and got.dtype == np.uint8
    np.testing.assert_array_equal(got, read_png(out))


@pytest.mark.parametrize("filter", ["aniso16", "ewa", "ripmap"])
def test_float_texture_storage_renders_the_same_image(filter):
    stored = texel.render("builtin:ground", filter=filter, size=(96, 54))
    float_ = texel.render("builtin:ground", filter=filter, size=(96, 54), texture_storage="float")
    np.testing.assert_array_equal(float_, stored)
    with pytest.raises(ValueError, match="texture_storage"):
        texel.render("builtin:ground", size=(8, 8), texture_storage="half")


def test_scene_text_renders_as_its_file():
    text = (ROOT / "scenes" / "ground.toml").read_text()
    a = texel.render(text, size=(48, 27))
    b = texel.render(str(ROOT / "scenes" / "ground.toml"), size=(48, 27))
    np.testing.assert_array_equal(a, b)


def test_reference_equals_the_cli_png_and_its_error_bars_hold(cli, tmp_path):
    out = tmp_path / "ref.png"
    cli("reference", "builtin:ground", "--size", "64x36", "--spp", "16", "--max-spp", "64",
        "-o", out)
    est = texel.reference_estimate("builtin:ground", spp=16, max_spp=64, size=(64, 36))
    np.testing.assert_array_equal(est["image"], read_png(out))
    np.testing.assert_array_equal(
        texel.reference("builtin:ground", spp=16, max_spp=64, size=(64, 36)), est["image"]
    )
    assert est["spp"].min() >= 16 and est["spp"].max() <= 64
    assert est["std_error"].shape == (36, 64, 4) and np.all(est["std_error"] >= 0)
    # The image is the encoding of the linear mean.
    np.testing.assert_array_equal(texel.encode(est["linear"], color="srgb"), est["image"])


def test_the_exact_reference_equals_the_cli_png_and_has_no_error(cli, tmp_path):
    out = tmp_path / "exact.png"
    cli("reference", "builtin:cube", "--size", "64x36", "--spp", "16", "--max-spp", "16",
        "--exact", "-o", out)
    est = texel.reference_estimate("builtin:cube", spp=16, max_spp=16, size=(64, 36), exact=True)
    np.testing.assert_array_equal(est["image"], read_png(out))
    exact = est["exact"]
    assert exact.dtype == np.bool_ and exact.shape == (36, 64)
    # The cube and its background are computed; only pixels where faces meet at the silhouette
    # may be sampled.
    assert exact.mean() > 0.95
    assert np.all(est["std_error"][exact] == 0) and np.all(est["spp"][exact] == 0)
    assert np.all(est["spp"][~exact] == 16)
    plain = texel.reference_estimate("builtin:cube", spp=16, max_spp=16, size=(64, 36))
    assert not plain["exact"].any()
    np.testing.assert_array_equal(est["linear"][~exact], plain["linear"][~exact])


def test_a_scissored_reference_is_that_part_of_the_whole():
    whole = texel.reference_estimate("builtin:ground", spp=16, max_spp=64, size=(40, 24))
    part = texel.reference_estimate(
        "builtin:ground", spp=16, max_spp=64, size=(40, 24), scissor=(7, 10, 31, 24)
    )
    for key in ("image", "linear", "std_error", "spp", "converged"):
        np.testing.assert_array_equal(part[key], whole[key][10:24, 7:31], err_msg=key)


def test_compare_scores_what_the_cli_reports(cli, tmp_path):
    filters = ["nearest", "trilinear", "aniso16"]
    cli("compare", "builtin:ground", "--size", "64x36", "--spp", "16", "--filters",
        ",".join(filters), "--out", tmp_path / "report")
    report = json.loads((tmp_path / "report" / "report.json").read_text())
    rows = {r["name"]: r for r in report["rows"]}
    got = texel.compare("builtin:ground", filters=filters, spp=16, size=(64, 36))
    assert list(got) == filters
    for name in filters:
        assert got[name]["psnr"] == pytest.approx(rows[name]["psnr_all"], abs=1e-9)
        assert got[name]["ssim"] == pytest.approx(rows[name]["ssim"], abs=1e-12)
        assert got[name]["texels_per_pixel"] == pytest.approx(
            rows[name]["texels_per_pixel_mean"], abs=1e-9
        )
        assert got[name]["ms_per_frame"] > 0
        assert got[name]["psnr"] < got[name]["noise_floor"] + 1e-9
    # Nearest aliases at the horizon: trilinear and aniso16 score higher.
    assert got["aniso16"]["psnr"] > got["nearest"]["psnr"]
    assert got["trilinear"]["texels_per_pixel"] > got["nearest"]["texels_per_pixel"]


def test_the_readme_example_runs(capsys):
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## From Python"):]
    code = section.split("```python\n", 1)[1].split("```", 1)[0]
    exec(compile(code, "README.md", "exec"), {})
    assert "dB against" in capsys.readouterr().out


def test_a_path_is_decided_by_the_file_not_by_the_string(tmp_path):
    solid_png(tmp_path / "red.png", (255, 0, 0))
    text = SCENE_HEAD + '[textures.red]\npath = "red.png"\n' + quad_mesh("red")
    plain = tmp_path / "scene.toml"
    plain.write_text(text)
    odd = tmp_path / "a\nscene.toml"
    odd.write_text(text)
    expected = texel.render(str(plain))
    assert tuple(expected[12, 16]) == (255, 0, 0, 255)
    # An existing file whose name holds a line break is the file, not TOML text.
    np.testing.assert_array_equal(texel.render(str(odd)), expected)
    np.testing.assert_array_equal(texel.render(odd), expected)
    # An os.PathLike is always a path, even one that names no file.
    with pytest.raises(OSError, match="(?i)no such file"):
        texel.render(tmp_path / "missing\nfile.toml")


@pytest.mark.parametrize("kind", ["obj", "gltf", "glb", "GLB"])
def test_mesh_files_render_framed_by_a_camera_of_their_own(tmp_path, kind):
    red = np.full((4, 4, 4), [255, 0, 0, 255], np.uint8)
    if kind == "obj":
        path = tmp_path / "quad.obj"
        write_obj(path)
    else:
        (tmp_path / "img").mkdir()
        (tmp_path / "img" / "red.png").write_bytes(png_bytes(red))
        path = tmp_path / f"quad.{kind}"
        write_gltf(path, png_bytes(red), image_uri="img/red.png", buffer_uri="quad.bin")
    assert texel.scene_size(path) == (640, 480)
    image = texel.render(str(path), size=(64, 48))
    np.testing.assert_array_equal(texel.render(path, size=(64, 48)), image)
    if kind == "obj":
        # texel reads no OBJ materials: the procedural checker, its white checks on the mesh.
        assert np.any(image[12:36, 20:44, :3] > 0)
    else:
        # The glTF's own material and texture, at the frame's centre.
        assert tuple(image[24, 32]) == (255, 0, 0, 255)
    # The frame's corners see past the mesh's bounding sphere: the background.
    assert tuple(image[0, 0]) == (0, 0, 0, 255)
    # Its files are the mesh's own.
    files = [pathlib.Path(f).name for f in texel.scene_files(path)]
    assert files[0] == path.name
    if kind == "gltf":
        assert sorted(files[1:]) == ["quad.bin", "red.png"]
    elif kind != "obj":
        assert files == [path.name]
