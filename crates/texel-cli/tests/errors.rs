//! Usage and input errors: exit code, the key part of the one-line message, never a panic.

use texel::quality::Image8;

use crate::util::*;

#[test]
fn error_unknown_filter_lists_the_valid_ones() {
    let d = Dir::new("err-filter");
    let out = d.arg("x.png");
    let all = FILTERS.join(", ");
    // clap rejects --filter itself, listing the possible values.
    fails(
        &["render", "--filter", "lanczos", "-o", &out],
        2,
        &["lanczos", &all],
    );
    fails(
        &[
            "warp",
            "in.png",
            "--corners",
            "0,0,1,0,1,1,0,1",
            "--filter",
            "box",
            "-o",
            &out,
        ],
        2,
        &["box", &all],
    );
    // Lists are parsed by texel.
    let msg = format!("unknown filter \"lanczos\": valid filters are {all}, or all");
    fails(
        &[
            "compare",
            "--filters",
            "nearest,lanczos",
            "--out",
            &d.arg("c"),
        ],
        1,
        &[&msg],
    );
    fails(&["bench", "--filters", "lanczos", "--json"], 1, &[&msg]);
    fails(&["render", "--lab-mode", "9", "-o", &out], 2, &["9"]);
    assert!(
        !d.join("c").exists(),
        "compare created its output before checking the filters"
    );
}

#[test]
fn error_malformed_toml_gives_line_and_column() {
    let d = Dir::new("err-toml");
    let scene = d.write("bad.toml", "[output]\nwidth = 64\nheight = = 36\n");
    let out = d.arg("x.png");
    fails(
        &["render", &scene.to_string_lossy(), "-o", &out],
        1,
        &[&format!("{}:3:10:", scene.display())],
    );
    // An unknown key is reported where it is.
    let scene = d.write("key.toml", format!("{HEAD}{TRIANGLE}colour = 3\n"));
    let line = HEAD.lines().count() + TRIANGLE.lines().count() + 1;
    fails(
        &["render", &scene.to_string_lossy(), "-o", &out],
        1,
        &[&format!("key.toml:{line}:1:"), "colour"],
    );
    fails(
        &["render", "builtin:nothing", "-o", &out],
        1,
        &["unknown built-in scene \"nothing\"", "ground"],
    );
    fails(
        &["render", &d.arg("none.toml"), "-o", &out],
        1,
        &[&d.arg("none.toml")],
    );
    assert!(!d.join("x.png").exists());
}

#[test]
fn error_missing_texture_file_names_its_path() {
    let d = Dir::new("err-texture");
    let body = HEAD.replace(
        "procedural = \"checker\"\nsize = 64\nchecks = 4",
        "path = \"textures/brick.png\"",
    );
    let scene = d.write("s.toml", format!("{body}{TRIANGLE}"));
    let path = d.join("textures/brick.png");
    fails(
        &["render", &scene.to_string_lossy(), "-o", &d.arg("x.png")],
        1,
        &["textures.t", &path.to_string_lossy()],
    );
}

#[test]
fn error_texture_over_the_size_limit() {
    let d = Dir::new("err-big");
    let body = HEAD.replace("size = 64", "size = 100000");
    let scene = d.write("s.toml", format!("{body}{TRIANGLE}"));
    fails(
        &["render", &scene.to_string_lossy(), "-o", &d.arg("x.png")],
        1,
        &["textures.t", "100000x100000", "16384"],
    );
}

#[test]
fn error_mesh_index_out_of_range() {
    let d = Dir::new("err-index");
    let scene = d.write(
        "s.toml",
        format!(
            "{HEAD}{}",
            TRIANGLE.replace("[[0, 1, 2]]", "[[0, 1, 2], [2, 1, 7]]")
        ),
    );
    fails(
        &["render", &scene.to_string_lossy(), "-o", &d.arg("x.png")],
        1,
        &["meshes[0].triangles[1] uses vertex index 7, but the mesh has only 3 vertices"],
    );
}

#[test]
fn error_sphere_mapping_past_the_pole_and_valid_ones_render() {
    let d = Dir::new("err-sphere-uv");
    let scene = d.write(
        "s.toml",
        format!("{HEAD}{TRIANGLE}sphere_uv = \"mercator\"\nmercator_cut_deg = 90.0\n"),
    );
    fails(
        &["render", &scene.to_string_lossy(), "-o", &d.arg("x.png")],
        1,
        &["meshes[0]", "mercator_cut_deg 90", "outside (0, 89.9]"],
    );
    assert!(!d.join("x.png").exists());
    // A valid mapping on a file mesh renders per pixel and per vertex.
    let scene = d.write(
        "t.toml",
        format!("{HEAD}{TRIANGLE}sphere_uv = \"equirect\"\nsphere_centre = [0.0, 0.0, -1.0]\n"),
    );
    for at in ["pixel", "vertex"] {
        ok(&[
            "render",
            &scene.to_string_lossy(),
            "--surface-uv",
            at,
            "-o",
            &d.arg("y.png"),
        ]);
    }
}

/// Bytes that are neither OBJ, glTF JSON, GLB nor PNG.
fn garbage() -> Vec<u8> {
    (0u32..512)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
        .chain([0, 0xff, 0xfe])
        .collect()
}

#[test]
fn error_unreadable_obj_and_gltf() {
    let d = Dir::new("err-mesh-files");
    let out = d.arg("x.png");
    for (key, file, kind) in [
        ("obj", "m.obj", "OBJ"),
        ("gltf", "m.gltf", "glTF"),
        ("gltf", "m.glb", "glTF"),
    ] {
        let path = d.write(file, garbage());
        let scene = d.write(
            "s.toml",
            format!("{HEAD}\n[[meshes]]\ntexture = \"t\"\n{key} = \"{file}\"\n"),
        );
        fails(
            &["render", &scene.to_string_lossy(), "-o", &out],
            1,
            &[&path.to_string_lossy(), &format!("cannot load {kind}")],
        );
        // A mesh file that does not exist.
        let scene = d.write(
            "s.toml",
            format!("{HEAD}\n[[meshes]]\ntexture = \"t\"\n{key} = \"gone-{file}\"\n"),
        );
        fails(
            &["render", &scene.to_string_lossy(), "-o", &out],
            1,
            &[&d.arg(&format!("gone-{file}"))],
        );
    }
    // A glTF whose external buffer is missing.
    d.write("nobin.gltf", quad_gltf("missing.bin"));
    let scene = d.write(
        "s.toml",
        format!("{HEAD}\n[[meshes]]\ntexture = \"t\"\ngltf = \"nobin.gltf\"\n"),
    );
    fails(
        &["render", &scene.to_string_lossy(), "-o", &out],
        1,
        &["nobin.gltf", "cannot load glTF"],
    );
    // An OBJ without texture coordinates.
    d.write("nouv.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let scene = d.write(
        "s.toml",
        format!("{HEAD}\n[[meshes]]\ntexture = \"t\"\nobj = \"nouv.obj\"\n"),
    );
    fails(
        &["render", &scene.to_string_lossy(), "-o", &out],
        1,
        &["nouv.obj", "texture coordinates"],
    );
    assert!(!d.join("x.png").exists());
}

#[test]
fn error_unwritable_output_path() {
    let d = Dir::new("err-write");
    let missing_dir = d.join("no/such/dir/x.png");
    let m = missing_dir.to_string_lossy().into_owned();
    fails(
        &["render", "--size", "32x18", "-o", &m],
        1,
        &["cannot write", &m],
    );
    fails(
        &[
            "reference",
            "--size",
            "32x18",
            "--spp",
            "1",
            "--max-spp",
            "1",
            "-o",
            &m,
        ],
        1,
        &["cannot write", &m],
    );
    fails(
        &["render", "--size", "32x18", "-o", "/proc/texel-test.png"],
        1,
        &["/proc/texel-test.png"],
    );
    let src = grey_png(&d, "src.png");
    fails(
        &[
            "warp",
            &src.to_string_lossy(),
            "--corners",
            "0,0,8,0,8,8,0,8",
            "-o",
            &m,
        ],
        1,
        &["cannot write", &m],
    );
    // An output directory that cannot be created (its parent is a file).
    d.write("file", "x");
    let under_file = d.arg("file/out");
    fails(
        &["mips", &src.to_string_lossy(), "--out", &under_file],
        1,
        &["Not a directory", &under_file],
    );
    fails(
        &[
            "compare",
            "--size",
            "32x18",
            "--spp",
            "1",
            "--filters",
            "nearest",
            "--out",
            &under_file,
        ],
        1,
        &["Not a directory", &under_file],
    );
    fails(
        &[
            "demo",
            "--size",
            "32x18",
            "--spp",
            "1",
            "--out",
            &under_file,
        ],
        1,
        &["Not a directory", &under_file],
    );
}

#[test]
fn error_corrupt_png_for_warp_and_mips() {
    let d = Dir::new("err-png");
    let mut bytes = b"\x89PNG\r\n\x1a\n".to_vec();
    bytes.extend(garbage());
    let png = d.write("broken.png", bytes);
    let p = png.to_string_lossy().into_owned();
    fails(
        &[
            "warp",
            &p,
            "--corners",
            "0,0,1,0,1,1,0,1",
            "-o",
            &d.arg("w.png"),
        ],
        1,
        &["cannot load image", &p],
    );
    fails(
        &["mips", &p, "--out", &d.arg("m")],
        1,
        &["cannot load texture", &p],
    );
    // Truncated: a valid PNG cut in half.
    let whole = d.join("whole.png");
    Image8::from_fn(64, 64, |x, y| [x as u8, y as u8, 0, 255])
        .unwrap()
        .write_png(&whole)
        .unwrap();
    let full = file_bytes(&whole);
    let half = d.write("half.png", &full[..full.len() / 2]);
    fails(
        &["mips", &half.to_string_lossy(), "--out", &d.arg("m")],
        1,
        &["cannot load texture", &half.to_string_lossy()],
    );
    // A missing input.
    fails(
        &[
            "warp",
            &d.arg("none.png"),
            "--corners",
            "0,0,1,0,1,1,0,1",
            "-o",
            &d.arg("w.png"),
        ],
        1,
        &[&d.arg("none.png")],
    );
    // A corrupt --extra image.
    fails(
        &compare_extra(&format!("gpu={p}"), &d.arg("c")),
        1,
        &["--extra", &p],
    );
    assert!(!d.join("w.png").exists() && !d.join("m").exists());
}

#[test]
fn error_bad_size() {
    let d = Dir::new("err-size");
    let out = d.arg("x.png");
    for (size, needle) in [
        ("0x10", "between 1 and 16384"),
        ("99999x10", "between 1 and 16384"),
        ("64", "WIDTHxHEIGHT"),
        ("axb", "not a whole number"),
    ] {
        fails(&["render", "--size", size, "-o", &out], 2, &[size, needle]);
        fails(
            &["demo", "--size", size, "--out", &d.arg("demo")],
            2,
            &[size, needle],
        );
    }
    // An --extra image of another size than the comparison.
    let extra = d.join("extra.png");
    Image8::filled(10, 10, [0, 0, 0, 255])
        .unwrap()
        .write_png(&extra)
        .unwrap();
    fails(
        &compare_extra(&format!("gpu={}", extra.display()), &d.arg("c")),
        1,
        &["10x10", "32x18"],
    );
    fails(
        &["compare", "--extra", "no-label.png", "--out", &d.arg("c")],
        1,
        &["LABEL=IMAGE"],
    );
    // A label equal to one of --gpu's rows is refused before any work: no GPU is asked for.
    let mut gpu = compare_extra(&format!("hw-trilinear={}", extra.display()), &d.arg("c"));
    gpu.push("--gpu".into());
    fails(&gpu, 1, &["\"hw-trilinear\" is given twice"]);
    assert!(!d.join("c").exists());
}

/// A wide texture's stacked levels 1.. (ending in 1-row levels) are taller than level 0: the chain
/// image grows to hold them (64 x 8: 4 + 2 + 1 + 1 + 1 + 1 = 10 rows).
#[test]
fn mips_of_a_wide_texture() {
    let d = Dir::new("mips-wide");
    let input = d.join("wide.png");
    Image8::from_fn(64, 8, |x, y| [(x * 4) as u8, (y * 30) as u8, 128, 255])
        .unwrap()
        .write_png(&input)
        .unwrap();
    let out = d.join("mips");
    ok(&[
        "mips",
        &input.to_string_lossy(),
        "--out",
        &out.to_string_lossy(),
    ]);
    assert_eq!(load(out.join("chain.png")).size(), (64 + 32, 10));
}

/// A warp larger than the pixel cap is refused before anything is allocated.
#[test]
fn error_warp_too_large() {
    let d = Dir::new("err-warp-size");
    let src = grey_png(&d, "src.png");
    fails(
        &[
            "warp",
            &src.to_string_lossy(),
            "--corners",
            "0,0,8,0,8,8,0,8",
            "--size",
            "16384x16384",
            "-o",
            &d.arg("x.png"),
        ],
        1,
        &["invalid --size", "16384x16384"],
    );
    assert!(!d.join("x.png").exists());
}

#[test]
fn error_bad_corners() {
    let d = Dir::new("err-corners");
    let src = grey_png(&d, "src.png");
    let s = src.to_string_lossy().into_owned();
    let out = d.arg("x.png");
    // A bow tie (top-right and bottom-right swapped) and all four points on one line.
    for c in ["0,0,8,8,8,0,0,8", "0,0,1,1,2,2,3,3"] {
        fails(
            &["warp", &s, "--corners", c, "-o", &out],
            1,
            &["invalid --corners", "convex"],
        );
    }
    fails(
        &["warp", &s, "--corners", "0,0,8,0,8,8", "-o", &out],
        2,
        &["has 6 numbers; give 8"],
    );
    fails(
        &["warp", &s, "--corners", "0,0,8,0,8,8,0,inf", "-o", &out],
        2,
        &["\"inf\"", "not a finite number"],
    );
    fails(&["warp", &s, "-o", &out], 2, &["--corners"]);
    assert!(!d.join("x.png").exists());
}

#[test]
fn any_reference_spp_splits_into_passes() {
    let d = Dir::new("err-spp");
    // Any count splits into passes (67 = 67 passes of one sample), for `texel reference` and
    // `compare --sampled-reference` alike; the comparison's reference is the same image.
    ok(&[
        "reference",
        "--size",
        "32x18",
        "--spp",
        "67",
        "--max-spp",
        "67",
        "-o",
        &d.arg("r67.png"),
    ]);
    ok(&[
        "compare",
        "--size",
        "32x18",
        "--spp",
        "67",
        "--filters",
        "nearest",
        "--sampled-reference",
        "--out",
        &d.arg("c"),
    ]);
    assert_eq!(load(d.join("r67.png")), load(d.join("c/reference.png")));
    fails(
        &["reference", "--spp", "0", "-o", &d.arg("r.png")],
        2,
        &["0"],
    );
    assert!(!d.join("r.png").exists());
}
