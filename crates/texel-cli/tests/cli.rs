//! Every command on small sizes, every usage error (exit code, the key part of the one-line
//! message, no panic), atomic outputs, the shipped ground scene, OBJ and glTF files written here,
//! the compare report against the images it wrote, and the filter ranking on the ground plane.

use texel_quality::{psnr, psnr_band, ssim, Image8, Mask, Report, OUTSIDE};

use crate::util::*;

// ---------------------------------------------------------------------------------------------
// Help
// ---------------------------------------------------------------------------------------------

#[test]
fn every_command_has_help_with_an_example() {
    let commands = [
        "render",
        "reference",
        "compare",
        "warp",
        "mips",
        "demo",
        "bench",
    ];
    let top = stdout(&ok(&["--help"]));
    for c in commands {
        assert!(top.contains(c), "top-level help lacks {c}: {top}");
        let help = stdout(&ok(&[c, "--help"]));
        assert!(
            help.contains(&format!("Example: texel {c} ")),
            "texel {c} --help: {help}"
        );
        assert!(help.contains("Usage: texel "), "{help}");
    }
}

// ---------------------------------------------------------------------------------------------
// render
// ---------------------------------------------------------------------------------------------

#[test]
fn render_every_filter_and_lab_mode() {
    let d = Dir::new("render-filters");
    let mut images = Vec::new();
    for f in FILTERS {
        let out = d.arg(&format!("{f}.png"));
        ok(&["render", "--size", "64x36", "--filter", f, "-o", &out]);
        let img = load(&out);
        assert_eq!(img.size(), (64, 36), "{f}");
        images.push(img);
    }
    // The default scene is the ground plane, and different filters give different images.
    assert_ne!(images[0], images[4], "nearest and trilinear render alike");
    assert_ne!(images[4], images[9], "trilinear and ewa render alike");
    // The lab's numbered modes are the named filters.
    let lab = [
        "nearest",
        "bilinear",
        "mip-nearest",
        "trilinear",
        "aniso2",
        "aniso4",
        "aniso8",
        "aniso16",
    ];
    for (k, name) in lab.iter().enumerate() {
        let mode = (k + 1).to_string();
        let out = d.arg(&format!("lab{mode}.png"));
        ok(&[
            "render",
            "builtin:ground",
            "--size",
            "64x36",
            "--lab-mode",
            &mode,
            "-o",
            &out,
        ]);
        assert_eq!(
            file_bytes(&out),
            file_bytes(d.join(&format!("{name}.png"))),
            "--lab-mode {mode} is not {name}"
        );
    }
}

#[test]
fn render_every_view() {
    let d = Dir::new("render-views");
    let views = [
        "color",
        "uv",
        "mip",
        "lod",
        "aniso",
        "fetches",
        "barycentric",
    ];
    let mut images = Vec::new();
    for v in views {
        let out = d.arg(&format!("{v}.png"));
        ok(&[
            "render", "--size", "64x36", "--filter", "aniso16", "--view", v, "-o", &out,
        ]);
        let img = load(&out);
        assert_eq!(img.size(), (64, 36), "{v}");
        images.push(img);
    }
    for i in 0..views.len() {
        for j in i + 1..views.len() {
            assert_ne!(
                images[i], images[j],
                "--view {} and --view {} render alike",
                views[i], views[j]
            );
        }
    }
}

#[test]
fn render_options_derivatives_perspective_color_threads() {
    let d = Dir::new("render-options");
    let render = |name: &str, extra: &[&str]| -> Vec<u8> {
        let out = d.arg(name);
        let mut args = vec!["render", "builtin:ground", "--size", "80x45"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", &out]);
        ok(&args);
        assert_eq!(load(&out).size(), (80, 45));
        file_bytes(&out)
    };
    let base = render("base.png", &["--filter", "trilinear"]);
    // The number of threads does not change the image.
    assert_eq!(
        render("t1.png", &["--filter", "trilinear", "--threads", "1"]),
        base
    );
    assert_eq!(
        render("t3.png", &["--filter", "trilinear", "--threads", "3"]),
        base
    );
    // Quad derivatives change the level of detail, affine interpolation the whole plane.
    assert_ne!(
        render(
            "quad.png",
            &["--filter", "trilinear", "--derivatives", "quad"]
        ),
        base
    );
    assert_ne!(
        render(
            "affine.png",
            &["--filter", "trilinear", "--perspective", "affine"]
        ),
        base
    );
    // --color raw: the black and white checks are 0 and 255 either way, so nearest is unchanged;
    // filtered greys are linear bytes (0.5 -> 128) instead of sRGB (0.5 -> 188), so trilinear changes.
    assert_eq!(
        render("near-raw.png", &["--filter", "nearest", "--color", "raw"]),
        render("near.png", &["--filter", "nearest"])
    );
    assert_ne!(
        render("raw.png", &["--filter", "trilinear", "--color", "raw"]),
        base
    );
}

#[test]
fn shipped_ground_scene_renders_like_the_builtin() {
    let d = Dir::new("ground-file");
    let (file, builtin, default) = (
        d.arg("file.png"),
        d.arg("builtin.png"),
        d.arg("default.png"),
    );
    ok(&[
        "render",
        &ground_toml(),
        "--size",
        "96x54",
        "--filter",
        "ewa",
        "-o",
        &file,
    ]);
    ok(&[
        "render",
        "builtin:ground",
        "--size",
        "96x54",
        "--filter",
        "ewa",
        "-o",
        &builtin,
    ]);
    ok(&[
        "render", "--size", "96x54", "--filter", "ewa", "-o", &default,
    ]);
    assert_eq!(load(&file).size(), (96, 54));
    assert_eq!(file_bytes(&file), file_bytes(&builtin));
    assert_eq!(file_bytes(&default), file_bytes(&builtin));
    // The black background above the horizon, the plane's checks resolved in the bottom row.
    let img = load(&file);
    assert_eq!(img.pixel(48, 0), Some([0, 0, 0, 255]));
    let bottom: Vec<u8> = (0..96).map(|x| img.pixel(x, 53).unwrap()[0]).collect();
    assert!(
        bottom.iter().any(|&v| v > 200) && bottom.iter().any(|&v| v < 80),
        "{bottom:?}"
    );
}

// ---------------------------------------------------------------------------------------------
// OBJ and glTF meshes written here
// ---------------------------------------------------------------------------------------------

/// The quad as OBJ: the same vertices in the same order; OBJ's v axis points up, so vt = 1 - v.
pub(crate) const QUAD_OBJ: &str = "# unit quad\n\
v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";

/// The quad's glTF buffer: 4 positions (48 bytes), 4 uvs (32), 6 u16 indices (12).
pub(crate) fn quad_buffer() -> Vec<u8> {
    let mut b = Vec::new();
    for v in [
        -1.0f32, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0, -1.0, 1.0, 0.0,
    ] {
        b.extend(v.to_le_bytes());
    }
    for v in [0.0f32, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0] {
        b.extend(v.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        b.extend(i.to_le_bytes());
    }
    b
}

pub(crate) fn quad_gltf(uri: &str) -> String {
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "indices": 2}}]}}],
  "buffers": [{{"uri": "{uri}", "byteLength": 92}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 32}},
    {{"buffer": 0, "byteOffset": 80, "byteLength": 12}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]
}}"#
    )
}

/// Standard base64 with padding (RFC 4648), for a glTF data URI.
pub(crate) fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

#[test]
fn base64_known_values() {
    assert_eq!(base64(b""), "");
    assert_eq!(base64(b"f"), "Zg==");
    assert_eq!(base64(b"fo"), "Zm8=");
    assert_eq!(base64(b"foo"), "Zm9v");
    assert_eq!(base64(b"foobar"), "Zm9vYmFy");
}

#[test]
fn obj_and_gltf_meshes_render_like_the_inline_quad() {
    let d = Dir::new("meshes");
    d.write("quad.obj", QUAD_OBJ);
    d.write("quad.bin", quad_buffer());
    d.write("external.gltf", quad_gltf("quad.bin"));
    d.write(
        "embedded.gltf",
        quad_gltf(&format!(
            "data:application/octet-stream;base64,{}",
            base64(&quad_buffer())
        )),
    );
    let mesh = |source: &str| format!("{HEAD}\n[[meshes]]\ntexture = \"t\"\n{source}\n");
    d.write("inline.toml", format!("{HEAD}{QUAD}"));
    d.write("obj.toml", mesh("obj = \"quad.obj\""));
    d.write("external.toml", mesh("gltf = \"external.gltf\""));
    d.write("embedded.toml", mesh("gltf = \"embedded.gltf\""));
    let mut images = Vec::new();
    for name in ["inline", "obj", "external", "embedded"] {
        let out = d.arg(&format!("{name}.png"));
        ok(&[
            "render",
            &d.arg(&format!("{name}.toml")),
            "--filter",
            "trilinear",
            "-o",
            &out,
        ]);
        images.push((name, file_bytes(&out)));
    }
    for (name, bytes) in &images[1..] {
        assert!(
            bytes == &images[0].1,
            "{name} renders differently from the inline quad"
        );
    }
    // The quad is actually drawn: black and white checks in the middle, blue background at the corner.
    let img = load(d.join("inline.png"));
    assert_eq!(img.size(), (64, 48));
    assert_eq!(img.pixel(0, 0), Some([0, 0, 255, 255]));
    let inside: Vec<[u8; 4]> = (16..48)
        .flat_map(|x| (12..36).map(move |y| (x, y)))
        .map(|(x, y)| img.pixel(x, y).unwrap())
        .collect();
    assert!(inside.contains(&[0, 0, 0, 255]) && inside.contains(&[255, 255, 255, 255]));
}

/// Without `--filter`, a glTF mesh is sampled with its own sampler's filters: a glTF asking for
/// NEAREST renders like `--filter nearest`, and differently from the trilinear default.
#[test]
fn gltf_sampler_filters_are_used_without_filter_flag() {
    let d = Dir::new("gltf-sampler");
    d.write("quad.bin", quad_buffer());
    let gltf = quad_gltf("quad.bin")
        .replace(r#""indices": 2}"#, r#""indices": 2, "material": 0}"#)
        .replace(
            r#""buffers":"#,
            r#""samplers": [{"magFilter": 9728, "minFilter": 9728}],
  "images": [{"uri": "never-loaded.png"}],
  "textures": [{"sampler": 0, "source": 0}],
  "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
  "buffers":"#,
        );
    d.write("nearest.gltf", gltf);
    d.write(
        "nearest.toml",
        format!("{HEAD}\n[[meshes]]\ntexture = \"t\"\ngltf = \"nearest.gltf\"\n"),
    );
    d.write(
        "plain.toml",
        format!("{HEAD}\n[[meshes]]\ntexture = \"t\"\ngltf = \"quad.gltf\"\n"),
    );
    d.write("quad.gltf", quad_gltf("quad.bin"));
    let render = |scene: &str, filter: Option<&str>, out: &str| {
        let mut args = vec!["render".to_string(), d.arg(scene)];
        if let Some(f) = filter {
            args.extend(["--filter".to_string(), f.to_string()]);
        }
        args.extend(["-o".to_string(), d.arg(out)]);
        ok(&args);
        file_bytes(d.arg(out))
    };
    let own = render("nearest.toml", None, "own.png");
    assert_eq!(
        own,
        render("nearest.toml", Some("nearest"), "forced-nearest.png")
    );
    assert_ne!(
        own,
        render("nearest.toml", Some("trilinear"), "forced-trilinear.png")
    );
    // A glTF without a sampler gets the trilinear default.
    assert_eq!(
        render("plain.toml", None, "plain.png"),
        render("plain.toml", Some("trilinear"), "plain-trilinear.png")
    );
}

// ---------------------------------------------------------------------------------------------
// reference
// ---------------------------------------------------------------------------------------------

#[test]
fn reference_is_sized_and_reproducible() {
    let d = Dir::new("reference");
    let (a, b) = (d.arg("a.png"), d.arg("b.png"));
    ok(&["reference", "--size", "64x36", "--spp", "16", "-o", &a]);
    ok(&[
        "reference",
        "builtin:ground",
        "--size",
        "64x36",
        "--spp",
        "16",
        "-o",
        &b,
    ]);
    assert_eq!(load(&a).size(), (64, 36));
    assert_eq!(
        file_bytes(&a),
        file_bytes(&b),
        "the reference's jitter is seeded: same bytes twice"
    );
    let raw = d.arg("raw.png");
    ok(&[
        "reference",
        "--size",
        "64x36",
        "--spp",
        "16",
        "--color",
        "raw",
        "-o",
        &raw,
    ]);
    assert_ne!(file_bytes(&raw), file_bytes(&a));
}

// ---------------------------------------------------------------------------------------------
// compare
// ---------------------------------------------------------------------------------------------

/// The coverage mask as the report used it, read back from a heat map: [`OUTSIDE`] marks the
/// uncovered pixels and viridis never reaches it.
fn coverage_from_heat_map(heat: &Image8) -> Mask {
    let bits = heat.pixels().iter().map(|p| *p != OUTSIDE).collect();
    Mask::new(heat.width(), heat.height(), bits).unwrap()
}

fn close(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= 1e-9 * a.abs().max(b.abs())
}

#[test]
fn compare_report_is_consistent_with_its_images() {
    let d = Dir::new("compare");
    // An image rendered elsewhere: texel's own bilinear image at the same size.
    let extra = d.arg("elsewhere.png");
    ok(&[
        "render", "--size", "96x54", "--filter", "bilinear", "-o", &extra,
    ]);
    let out = d.join("report");
    let out_s = out.to_string_lossy().into_owned();
    let run = ok(&[
        "compare",
        "builtin:ground",
        "--size",
        "96x54",
        "--spp",
        "16",
        "--filters",
        "nearest,bilinear,trilinear,ewa",
        "--extra",
        &format!("gpu={extra}"),
        "--out",
        &out_s,
    ]);
    // The Markdown table goes to stdout, the report's place to stderr.
    assert!(stdout(&run).contains("| trilinear |"), "{}", stdout(&run));
    assert!(stderr(&run).contains("index.html"));

    let report =
        Report::from_json(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!((report.width, report.height, report.spp), (96, 54, 16));
    assert_eq!(report.color, "srgb");
    let names: Vec<&str> = report.rows.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["nearest", "bilinear", "trilinear", "ewa", "gpu"]);
    let reference = load(out.join(&report.reference_image));
    assert_eq!(reference.size(), (96, 54));

    let mut coverage: Option<Mask> = None;
    for row in &report.rows {
        let image = load(out.join(&row.image));
        let heat = load(out.join(row.heat_map.as_ref().expect("every row has a heat map")));
        let mask = coverage_from_heat_map(&heat);
        // Every heat map shows the same coverage, part of the image (the plane below the horizon).
        match &coverage {
            None => {
                assert!(
                    mask.count() > 0 && mask.count() < 96 * 54,
                    "coverage {} pixels",
                    mask.count()
                );
                assert!(mask.get(48, 53) && !mask.get(48, 0));
                coverage = Some(mask.clone());
            }
            Some(c) => assert_eq!(&mask, c, "{}: another coverage", row.name),
        }
        // The scores are exactly those of the images written.
        let p = psnr(&reference, &image, Some(&mask)).unwrap();
        assert!(
            close(row.psnr_all, p),
            "{}: psnr_all {} but the images give {p}",
            row.name,
            row.psnr_all
        );
        let b = psnr_band(&reference, &image, &mask, report.band_rows).unwrap();
        assert!(
            close(row.psnr_band, b),
            "{}: psnr_band {} but the images give {b}",
            row.name,
            row.psnr_band
        );
        let s = ssim(&reference, &image, Some(&mask)).unwrap();
        assert!(
            close(row.ssim, s),
            "{}: ssim {} but the images give {s}",
            row.name,
            row.ssim
        );
        assert!(
            row.psnr_all.is_finite() && row.psnr_all > 5.0,
            "{}: {}",
            row.name,
            row.psnr_all
        );
        if let Some(crop) = &row.horizon_crop {
            assert!(out.join(crop).is_file());
        }
        if row.extra {
            assert!(
                row.ms_per_frame.is_none()
                    && row.texels_per_pixel_mean.is_none()
                    && row.texture_bytes.is_none()
            );
        } else {
            assert!(row.ms_per_frame.is_some_and(|ms| ms > 0.0), "{}", row.name);
            assert!(row.texture_bytes.is_some_and(|b| b > 0), "{}", row.name);
            let (mean, max) = (
                row.texels_per_pixel_mean.unwrap(),
                row.texels_per_pixel_max.unwrap(),
            );
            assert!(
                mean >= 1.0 && mean <= max as f64,
                "{}: mean {mean} max {max}",
                row.name
            );
        }
    }
    // Nearest reads one texel per pixel, bilinear four (the 2x2 quad).
    assert_eq!(report.rows[0].texels_per_pixel_mean, Some(1.0));
    assert_eq!(report.rows[0].texels_per_pixel_max, Some(1));
    assert_eq!(report.rows[1].texels_per_pixel_max, Some(4));
    // The extra image is copied unchanged and, being texel's bilinear image, scores as bilinear.
    let gpu = &report.rows[4];
    assert!(gpu.extra);
    assert_eq!(load(out.join(&gpu.image)), load(&extra));
    assert_eq!(load(&extra), load(out.join(&report.rows[1].image)));
    assert_eq!(
        (gpu.psnr_all, gpu.psnr_band, gpu.ssim),
        (
            report.rows[1].psnr_all,
            report.rows[1].psnr_band,
            report.rows[1].ssim
        )
    );

    // report.md has the same table; index.html shows every image.
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    for row in &report.rows {
        assert!(
            md.contains(&format!("{:.2}", row.psnr_all)),
            "report.md lacks {}'s PSNR",
            row.name
        );
        assert!(html.contains(&row.image), "index.html lacks {}", row.image);
    }
    assert!(md.contains("gpu (extra)"));
    assert!(html.contains("<svg"), "no chart in index.html");
    assert!(temp_files(&out).is_empty());
}

#[test]
fn ground_plane_filter_ranking_against_a_16x16_reference() {
    let d = Dir::new("ranking");
    let out = d.arg("report");
    ok(&[
        "compare",
        "builtin:ground",
        "--size",
        "192x108",
        "--spp",
        "256",
        "--filters",
        "nearest,bilinear,trilinear,aniso16,ewa",
        "--out",
        &out,
    ]);
    let report =
        Report::from_json(&std::fs::read_to_string(d.join("report/report.json")).unwrap()).unwrap();
    let psnr = |name: &str| {
        report
            .rows
            .iter()
            .find(|r| r.name == name)
            .unwrap()
            .psnr_all
    };
    let (n, b, t, a, e) = (
        psnr("nearest"),
        psnr("bilinear"),
        psnr("trilinear"),
        psnr("aniso16"),
        psnr("ewa"),
    );
    assert!(e > t && a > t, "ewa {e} aniso16 {a} trilinear {t}");
    assert!(t > b, "trilinear {t} bilinear {b}");
    assert!(b > n, "bilinear {b} nearest {n}");
}

// ---------------------------------------------------------------------------------------------
// warp
// ---------------------------------------------------------------------------------------------

#[test]
fn warp_identity_reproduces_the_image_and_size_is_respected() {
    let d = Dir::new("warp-identity");
    let src = Image8::from_fn(40, 24, |x, y| {
        [(x * 6) as u8, (y * 10) as u8, ((x * y) % 251) as u8, 255]
    })
    .unwrap();
    let input = d.join("in.png");
    src.write_png(&input).unwrap();
    let input = input.to_string_lossy().into_owned();
    // Output pixel centres land on source texel centres: nearest (and bilinear) give the source back.
    for f in ["nearest", "bilinear"] {
        let out = d.arg(&format!("{f}.png"));
        ok(&[
            "warp",
            &input,
            "--corners",
            "0,0,40,0,40,24,0,24",
            "--color",
            "raw",
            "--filter",
            f,
            "-o",
            &out,
        ]);
        assert_eq!(load(&out), src, "{f}");
    }
    let out = d.arg("small.png");
    ok(&[
        "warp",
        &input,
        "--corners",
        "-4,2,44,0,40,24,0,20",
        "--size",
        "20x12",
        "-o",
        &out,
    ]);
    assert_eq!(load(&out).size(), (20, 12));
    // Without --size the output has the source's size.
    let out = d.arg("tilted.png");
    ok(&[
        "warp",
        &input,
        "--corners",
        "5,0,35,3,40,24,0,24",
        "-o",
        &out,
    ]);
    assert_eq!(load(&out).size(), (40, 24));
}

#[test]
fn warp_shrinking_a_fine_checkerboard() {
    let d = Dir::new("warp-checker");
    // A 1-texel checkerboard, shrunk 5x: filtered, it is uniform grey; point-sampled, it aliases.
    let checker = Image8::from_fn(160, 160, |x, y| {
        if (x + y) % 2 == 0 {
            [0, 0, 0, 255]
        } else {
            [255; 4]
        }
    })
    .unwrap();
    let input = d.join("checker.png");
    checker.write_png(&input).unwrap();
    let input = input.to_string_lossy().into_owned();
    let warp = |filter: &str| -> Image8 {
        let out = d.arg(&format!("{filter}.png"));
        let c = "0,0,160,0,160,160,0,160";
        ok(&[
            "warp",
            &input,
            "--corners",
            c,
            "--size",
            "32x32",
            "--color",
            "raw",
            "--filter",
            filter,
            "-o",
            &out,
        ]);
        let img = load(&out);
        assert_eq!(img.size(), (32, 32));
        img
    };
    // Interior pixels only: the outermost ones see the transparent border.
    let interior = |img: &Image8| -> Vec<u8> {
        (1..31)
            .flat_map(|y| (1..31).map(move |x| (x, y)))
            .map(|(x, y)| img.pixel(x, y).unwrap()[0])
            .collect()
    };
    for filter in ["ewa", "trilinear"] {
        let img = warp(filter);
        for v in interior(&img) {
            assert!(
                v.abs_diff(128) <= 8,
                "{filter}: {v} is not grey (raw 0.5 = 128)"
            );
        }
    }
    let bilinear = interior(&warp("bilinear"));
    let (lo, hi) = (
        bilinear.iter().min().unwrap(),
        bilinear.iter().max().unwrap(),
    );
    assert!(
        *lo < 64 && *hi > 192,
        "bilinear should alias to black and white, got {lo}..{hi}"
    );
}

// ---------------------------------------------------------------------------------------------
// mips
// ---------------------------------------------------------------------------------------------

#[test]
fn mips_writes_every_level_and_the_chain() {
    let d = Dir::new("mips");
    // 16 x 8 of uniform 2x2 blocks: level 1 is exactly the block colours (raw bytes).
    let block = |x: u32, y: u32| [(x / 2 * 30) as u8, (y / 2 * 60) as u8, 200, 255];
    let src = Image8::from_fn(16, 8, block).unwrap();
    let input = d.join("tex.png");
    src.write_png(&input).unwrap();
    let out = d.join("mips");
    ok(&[
        "mips",
        &input.to_string_lossy(),
        "--color",
        "raw",
        "--out",
        &out.to_string_lossy(),
    ]);
    let sizes = [(16, 8), (8, 4), (4, 2), (2, 1), (1, 1)];
    let mut files: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    let mut expected: Vec<String> = sizes
        .iter()
        .enumerate()
        .map(|(k, (w, h))| format!("level-{k:02}-{w}x{h}.png"))
        .collect();
    expected.push("chain.png".to_string());
    expected.push(texel_quality::OUTPUT_MARKER.to_string());
    expected.sort();
    assert_eq!(files, expected);
    for (k, &(w, h)) in sizes.iter().enumerate() {
        assert_eq!(
            load(out.join(format!("level-{k:02}-{w}x{h}.png"))).size(),
            (w, h)
        );
    }
    assert_eq!(load(out.join("level-00-16x8.png")), src);
    assert_eq!(
        load(out.join("level-01-8x4.png")),
        Image8::from_fn(8, 4, |x, y| block(2 * x, 2 * y)).unwrap()
    );
    // The chain: level 0 on the left, the others stacked to its right.
    let chain = load(out.join("chain.png"));
    assert_eq!(chain.size(), (16 + 8, 8));
    assert_eq!(chain.pixel(16, 0), Some(block(0, 0)));
    assert_eq!(chain.pixel(23, 3), Some(block(14, 6)));

    // A non-power-of-two texture: floor(log2(20)) + 1 = 5 levels, the last one the mean colour.
    let odd = Image8::from_fn(20, 12, |x, y| {
        [(x * 12) as u8, (y * 20) as u8, ((x + y) * 7) as u8, 255]
    })
    .unwrap();
    let input = d.join("odd.png");
    odd.write_png(&input).unwrap();
    let out = d.join("odd");
    ok(&[
        "mips",
        &input.to_string_lossy(),
        "--color",
        "raw",
        "--out",
        &out.to_string_lossy(),
    ]);
    for (k, (w, h)) in [(20, 12), (10, 6), (5, 3), (2, 1), (1, 1)]
        .into_iter()
        .enumerate()
    {
        assert_eq!(
            load(out.join(format!("level-{k:02}-{w}x{h}.png"))).size(),
            (w, h)
        );
    }
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 7); // five levels, chain.png and the output marker
    let last = load(out.join("level-04-1x1.png")).pixel(0, 0).unwrap();
    for c in 0..3 {
        let mean = odd.pixels().iter().map(|p| f64::from(p[c])).sum::<f64>() / 240.0;
        assert!(
            (f64::from(last[c]) - mean).abs() <= 0.5 + 1e-3,
            "channel {c}: {} vs mean {mean}",
            last[c]
        );
    }
}

// ---------------------------------------------------------------------------------------------
// demo and bench
// ---------------------------------------------------------------------------------------------

#[test]
fn demo_compares_every_builtin_scene_with_an_index() {
    let d = Dir::new("demo");
    let out = d.arg("demo");
    let run = ok(&["demo", "--size", "64x36", "--spp", "4", "--out", &out]);
    assert!(stdout(&run).contains("index.html"), "{}", stdout(&run));
    let index = std::fs::read_to_string(d.join("demo/index.html")).unwrap();
    for scene in BUILTINS {
        assert!(
            index.contains(&format!("href=\"{scene}/index.html\"")),
            "index.html does not link {scene}"
        );
        let dir = d.join(&format!("demo/{scene}"));
        assert!(dir.join("index.html").is_file() && dir.join("report.md").is_file());
        let report =
            Report::from_json(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
        assert_eq!(
            (report.width, report.height, report.spp),
            (64, 36, 4),
            "{scene}"
        );
        let names: Vec<&str> = report.rows.iter().map(|r| r.name.as_str()).collect();
        assert_eq!(names, FILTERS, "{scene}");
        for row in &report.rows {
            assert_eq!(load(dir.join(&row.image)).size(), (64, 36));
        }
    }
    assert!(temp_files(&d.join("demo")).is_empty());
}

#[test]
fn bench_json_has_the_llvmpipe_shape() {
    let run = ok(&[
        "bench",
        "--size",
        "64x36",
        "--frames",
        "3",
        "--warmup",
        "1",
        "--threads",
        "1",
        "--filters",
        "nearest,trilinear,ewa",
        "--json",
    ]);
    let v: serde_json::Value =
        serde_json::from_str(&stdout(&run)).unwrap_or_else(|e| panic!("{e}: {}", stdout(&run)));
    let obj = v.as_object().unwrap();
    let mut keys: Vec<&str> = obj.keys().map(String::as_str).collect();
    keys.sort_unstable();
    assert_eq!(
        keys,
        [
            "clear_ms",
            "frames",
            "height",
            "median_ms",
            "renderer",
            "threads",
            "width"
        ]
    );
    assert_eq!(v["renderer"], "texel");
    assert_eq!(v["threads"], 1);
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(64), Some(36))
    );
    assert_eq!(v["frames"], 3);
    for key in ["median_ms", "clear_ms"] {
        let medians = v[key].as_object().unwrap();
        let mut filters: Vec<&str> = medians.keys().map(String::as_str).collect();
        filters.sort_unstable();
        assert_eq!(filters, ["ewa", "nearest", "trilinear"], "{key}");
        for (f, ms) in medians {
            assert!(
                ms.as_f64().is_some_and(|ms| ms.is_finite() && ms >= 0.0),
                "{key} {f}: {ms}"
            );
        }
    }
    // Without --json: a table with one line per filter.
    let run = ok(&[
        "bench",
        &ground_toml(),
        "--size",
        "64x36",
        "--frames",
        "1",
        "--filters",
        "bilinear,sat",
    ]);
    let text = stdout(&run);
    assert!(
        text.contains("median ms") && text.contains("\nbilinear ") && text.contains("\nsat "),
        "{text}"
    );
}

// ---------------------------------------------------------------------------------------------
// Errors: exit code, the key part of the message, never a panic
// ---------------------------------------------------------------------------------------------

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
        &["reference", "--size", "32x18", "--spp", "1", "-o", &m],
        1,
        &["cannot write", &m],
    );
    fails(
        &["render", "--size", "32x18", "-o", "/proc/texel-test.png"],
        1,
        &["/proc/texel-test.png"],
    );
    let src = d.join("src.png");
    Image8::filled(8, 8, [9, 9, 9, 255])
        .unwrap()
        .write_png(&src)
        .unwrap();
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
        &[
            "compare",
            "--size",
            "32x18",
            "--spp",
            "1",
            "--filters",
            "nearest",
            "--extra",
            &format!("gpu={p}"),
            "--out",
            &d.arg("c"),
        ],
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
        &[
            "compare",
            "--size",
            "32x18",
            "--spp",
            "1",
            "--filters",
            "nearest",
            "--extra",
            &format!("gpu={}", extra.display()),
            "--out",
            &d.arg("c"),
        ],
        1,
        &["10x10", "32x18"],
    );
    fails(
        &["compare", "--extra", "no-label.png", "--out", &d.arg("c")],
        1,
        &["LABEL=IMAGE"],
    );
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
    let src = d.join("src.png");
    Image8::filled(8, 8, [9, 9, 9, 255])
        .unwrap()
        .write_png(&src)
        .unwrap();
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
    let src = d.join("src.png");
    Image8::filled(8, 8, [9, 9, 9, 255])
        .unwrap()
        .write_png(&src)
        .unwrap();
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
fn error_reference_spp_unstratifiable() {
    let d = Dir::new("err-spp");
    // 8 = 2 x 4 and 512 = 16 x 32 stratify; a prime above 64 cannot within 64 per side.
    ok(&[
        "reference",
        "--size",
        "32x18",
        "--spp",
        "8",
        "-o",
        &d.arg("r8.png"),
    ]);
    fails(
        &[
            "reference",
            "--size",
            "32x18",
            "--spp",
            "67",
            "-o",
            &d.arg("r.png"),
        ],
        1,
        &["--spp 67", "1 x 67", "square root"],
    );
    fails(
        &["reference", "--spp", "0", "-o", &d.arg("r.png")],
        2,
        &["0"],
    );
    assert!(!d.join("r.png").exists());
}

// ---------------------------------------------------------------------------------------------
// Atomic outputs
// ---------------------------------------------------------------------------------------------

#[test]
fn failed_writes_leave_no_temporary_files() {
    let d = Dir::new("atomic");
    // The output path is an existing (non-empty) directory: the rename fails after the temporary file
    // was written, and the temporary file must be gone.
    std::fs::create_dir_all(d.join("out/x.png")).unwrap();
    d.write("out/x.png/keep", "keep");
    let x = d.arg("out/x.png");
    fails(
        &["render", "--size", "32x18", "-o", &x],
        1,
        &["cannot write", &x],
    );
    fails(
        &["reference", "--size", "32x18", "--spp", "1", "-o", &x],
        1,
        &["cannot write", &x],
    );
    let src = d.join("src.png");
    Image8::filled(8, 8, [9, 9, 9, 255])
        .unwrap()
        .write_png(&src)
        .unwrap();
    fails(
        &[
            "warp",
            &src.to_string_lossy(),
            "--corners",
            "0,0,8,0,8,8,0,8",
            "-o",
            &x,
        ],
        1,
        &["cannot write", &x],
    );
    assert_eq!(
        std::fs::read_to_string(d.join("out/x.png/keep")).unwrap(),
        "keep"
    );

    // compare failing after its filters' images were written (the --extra image is missing): the
    // report directory is never published, and its staging directory is gone.
    fails(
        &[
            "compare",
            "--size",
            "32x18",
            "--spp",
            "1",
            "--filters",
            "nearest",
            "--extra",
            &format!("gpu={}", d.arg("missing.png")),
            "--out",
            &d.arg("cmp"),
        ],
        1,
        &["missing.png"],
    );
    assert!(!d.join("cmp").exists());
    let left = temp_files(d.path());
    assert!(left.is_empty(), "temporary files left behind: {left:?}");
    // And a successful run leaves none either.
    ok(&["render", "--size", "32x18", "-o", &d.arg("out/ok.png")]);
    assert!(temp_files(d.path()).is_empty());
}
