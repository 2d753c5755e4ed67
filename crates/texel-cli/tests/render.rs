//! `texel render`: every filter, lab mode, view and option; the shipped ground scene.

use crate::util::*;

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

/// `--precision gpu` filters unorm8 textures (`--color raw`) in fixed point: within 3 codes of
/// exact and not identical to it on the textured ground; sRGB textures (the default colour
/// handling) keep the exact path, byte for byte; a bad value is refused.
#[test]
fn precision_gpu_changes_raw_frames_by_at_most_three_codes() {
    let d = Dir::new("render-precision");
    for filter in ["bilinear", "trilinear"] {
        let render = |color: &str, precision: &str| {
            let out = d.arg(&format!("{filter}-{color}-{precision}.png"));
            let args = ["render", "--size", "160x90", "--filter", filter];
            let more = ["--color", color, "--precision", precision, "-o", &out];
            ok(&[&args[..], &more[..]].concat());
            load(&out)
        };
        let (exact, gpu) = (render("raw", "exact"), render("raw", "gpu"));
        let diffs: Vec<u8> = exact
            .pixels()
            .iter()
            .zip(gpu.pixels())
            .flat_map(|(a, b)| (0..4).map(move |c| a[c].abs_diff(b[c])))
            .collect();
        let max = diffs.iter().copied().max().unwrap();
        assert!(max <= 3, "{filter}: {max} codes from exact");
        assert!(
            diffs.iter().any(|&x| x > 0),
            "{filter}: gpu precision changed nothing"
        );
        assert!(
            render("srgb", "exact") == render("srgb", "gpu"),
            "{filter}: sRGB changed"
        );
    }
    fails(&["render", "--precision", "half"], 2, &["half"]);
}

/// `--texture-storage float` decodes 8-bit textures once to `f32`: the bytes are the stored
/// textures' for every kind of filter, sRGB and raw, lit and unlit; a texture whose float copy
/// does not fit `--max-memory` stays 8-bit with a note (same bytes again); `float` with `--gpu`
/// is refused rather than ignored.
#[test]
fn float_texture_storage_renders_the_same_bytes() {
    let d = Dir::new("render-storage");
    let cases = [
        ("builtin:ground", "mip-nearest"),
        ("builtin:ground", "aniso16"),
        ("builtin:ground", "ewa"),
        ("builtin:ground", "ripmap"),
        ("builtin:glossy", "trilinear"),
        ("builtin:terrain", "aniso4"),
    ];
    for (scene, filter) in cases {
        for color in ["srgb", "raw"] {
            let render = |storage: &str, more: &[&str]| {
                let out = d.arg(&format!("{filter}-{color}-{storage}.png"));
                let args = ["render", scene, "--size", "96x54", "--filter", filter];
                let rest = ["--color", color, "--texture-storage", storage, "-o", &out];
                let o = texel(&[&args[..], more, &rest[..]].concat());
                assert!(o.status.success(), "{}", stderr(&o));
                (load(&out), stderr(&o))
            };
            let (stored, _) = render("stored", &[]);
            let (float, note) = render("float", &[]);
            assert!(stored == float, "{scene} {filter} {color}: images differ");
            assert!(!note.contains("stays 8-bit"), "{note}");
            if scene == "builtin:ground" && filter == "aniso16" {
                // The checker's pyramid: 5.3 MiB stored, 21.3 MiB as float.
                let (kept, note) = render("float", &["--max-memory", "16M"]);
                assert!(kept == stored, "{color}: kept-stored image differs");
                assert!(note.contains("\"checker\" stays 8-bit"), "{note}");
            }
        }
    }
    fails(
        &[
            "render",
            "--gpu",
            "--texture-storage",
            "float",
            "-o",
            &d.arg("g.png"),
        ],
        1,
        &["--texture-storage float", "--gpu"],
    );
    fails(
        &[
            "render",
            "--texture-storage",
            "float",
            "--precision",
            "gpu",
            "-o",
            &d.arg("p.png"),
        ],
        1,
        &["--texture-storage float", "--precision gpu"],
    );
    fails(&["render", "--texture-storage", "half"], 2, &["half"]);
}
