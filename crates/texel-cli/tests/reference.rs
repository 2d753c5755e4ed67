//! `texel reference`: size, reproducibility, error bars and refinement.

use crate::util::*;

#[test]
fn reference_is_sized_and_reproducible() {
    let d = Dir::new("reference");
    let (a, b) = (d.arg("a.png"), d.arg("b.png"));
    ok(&[
        "reference",
        "--size",
        "64x36",
        "--spp",
        "16",
        "--max-spp",
        "64",
        "-o",
        &a,
    ]);
    ok(&[
        "reference",
        "builtin:ground",
        "--size",
        "64x36",
        "--spp",
        "16",
        "--max-spp",
        "64",
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
        "--max-spp",
        "64",
        "--color",
        "raw",
        "-o",
        &raw,
    ]);
    assert_ne!(file_bytes(&raw), file_bytes(&a));
}

/// Linear RGBA floats of an OpenEXR file.
fn exr(path: &str) -> Vec<[f32; 4]> {
    image::open(path)
        .unwrap_or_else(|e| panic!("cannot read {path}: {e}"))
        .to_rgba32f()
        .pixels()
        .map(|p| p.0)
        .collect()
}

/// The glossy plane at 80 x 45 with `spp` samples a pixel and no refinement, seed `seed`:
/// (mean, standard error), both linear.
fn glossy(d: &Dir, seed: u32, spp: u32) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let (img, err) = (
        d.arg(&format!("g{seed}.exr")),
        d.arg(&format!("e{seed}.exr")),
    );
    let spp = spp.to_string();
    ok(&[
        "reference",
        "builtin:glossy",
        "--size",
        "80x45",
        "--spp",
        &spp,
        "--max-spp",
        &spp,
        "--seed",
        &seed.to_string(),
        "--error-map",
        &err,
        "-o",
        &img,
    ]);
    (exr(&img), exr(&err))
}

/// Two seeds give independent estimates whose difference the error bars explain: on the glossy
/// plane's lit pixels, `|a - b| <= 1.96 sqrt(se_a^2 + se_b^2)` for 80-99.5 % of the red values
/// (95 % if the error bars were exact; with 8 passes the estimated errors are themselves noisy, so
/// the share drops towards 90 %; a pixel whose passes all missed its glints reports too small an
/// error and falls outside).
#[test]
fn two_seeds_differ_within_their_error_bars() {
    let d = Dir::new("reference-seeds");
    let (a, sa) = glossy(&d, 1, 64);
    let (b, sb) = glossy(&d, 2, 64);
    let (mut n, mut inside) = (0, 0);
    for i in 0..a.len() {
        let se = (sa[i][0].powi(2) + sb[i][0].powi(2)).sqrt();
        if se > 0.0 {
            n += 1;
            inside += usize::from((a[i][0] - b[i][0]).abs() <= 1.96 * se);
        }
    }
    let share = inside as f64 / n as f64;
    eprintln!("{inside} of {n} pixels within 1.96 combined standard errors ({share:.3})");
    assert!(n > a.len() / 2, "too few noisy pixels: {n}");
    assert!((0.80..=0.995).contains(&share), "{share}");
    assert_ne!(a, b, "two seeds are two estimates");
}

/// The estimate is the same on one thread and on two; the error map's picture is the image's
/// size; `--max-spp` below `--spp` is refused.
#[test]
fn the_reference_does_not_depend_on_threads_and_writes_its_error_map() {
    let d = Dir::new("reference-threads");
    let run = |threads: &str, out: &str, map: &str| {
        let out = ok(&[
            "reference",
            "builtin:glossy",
            "--size",
            "48x27",
            "--spp",
            "16",
            "--max-spp",
            "64",
            "--tolerance",
            "2",
            "--threads",
            threads,
            "--error-map",
            &d.arg(map),
            "-o",
            &d.arg(out),
        ]);
        stderr(&out)
    };
    let summary = run("1", "one.png", "one-err.png");
    run("2", "two.png", "two-err.png");
    assert_eq!(file_bytes(d.join("one.png")), file_bytes(d.join("two.png")));
    assert_eq!(
        file_bytes(d.join("one-err.png")),
        file_bytes(d.join("two-err.png"))
    );
    assert_eq!(load(d.join("one-err.png")).size(), (48, 27));
    assert!(
        summary.contains("% of pixels within ±2/255") && summary.contains("16-"),
        "{summary}"
    );
    fails(
        &[
            "reference",
            "--spp",
            "64",
            "--max-spp",
            "16",
            "-o",
            &d.arg("x.png"),
        ],
        1,
        &["--max-spp 16 is below --spp 64"],
    );
    fails(
        &["reference", "--tolerance", "nan", "-o", &d.arg("x.png")],
        2,
        &["not a tolerance"],
    );
    // The error map may not replace the image: refused before any work, nothing written.
    let same = d.join("sub/../same.png");
    std::fs::create_dir(d.join("sub")).unwrap();
    fails(
        &[
            "reference",
            "--size",
            "16x9",
            "-o",
            &d.arg("same.png"),
            "--error-map",
            &same.to_string_lossy(),
        ],
        1,
        &["name the same file"],
    );
    assert!(!d.join("same.png").exists());
}

/// Refinement adds samples only where a pixel has not converged: on the unlit ground plane with a
/// loose tolerance, refining up to 256 samples raises the share converged over the fixed 16-sample
/// estimate while the mean count stays well below 256 (most pixels stop at the minimum), and the
/// PNG error map marks exactly the unconverged share in red.
#[test]
fn refinement_adds_samples_only_where_needed() {
    let d = Dir::new("reference-adaptive");
    let run = |max: &str| {
        let out = ok(&[
            "reference",
            "--size",
            "64x36",
            "--spp",
            "16",
            "--max-spp",
            max,
            "--tolerance",
            "1",
            "--error-map",
            &d.arg(&format!("err{max}.png")),
            "-o",
            &d.arg(&format!("r{max}.png")),
        ]);
        let line = stderr(&out);
        let field = |before: &str, after: char| -> f64 {
            line.split(before)
                .nth(1)
                .and_then(|s| s.split(after).next())
                .and_then(|s| s.trim().parse().ok())
                .unwrap_or_else(|| panic!("no {before:?} in {line}"))
        };
        let (share, mean) = (field("reference: ", '%'), field("(mean ", ')'));
        let red = load(d.join(&format!("err{max}.png")))
            .pixels()
            .iter()
            .filter(|p| **p == [255, 0, 0, 255])
            .count();
        let unconverged = 100.0 * red as f64 / (64.0 * 36.0);
        assert!(
            (share - (100.0 - unconverged)).abs() < 0.01,
            "{line}: {red} red"
        );
        (share, mean, line)
    };
    let (fixed, fixed_mean, _) = run("16");
    let (refined, refined_mean, line) = run("256");
    assert_eq!(fixed_mean, 16.0);
    assert!(refined > fixed, "{fixed} -> {refined}: {line}");
    assert!(refined_mean > 16.0 && refined_mean < 128.0, "{line}");
}

/// The display value (8-bit steps, clipped, sRGB) of a linear value.
fn display(x: f32) -> f64 {
    texel::texture::displayed(f64::from(x), true) * 255.0
}

/// Glints (`scenes/glints.toml`: a sharp lobe on a bumpy plane under a grazing light) at 48 x 27:
/// per-pixel estimates have a heavy right tail, and the display clips them, so a reference with too
/// few samples is biased dark. Against a brute force (192 x 108 at 1024 samples, box-averaged 4 x 4
/// in linear light: 16 384 samples a pixel) the converging reference's 4 x 4 block means of the
/// displayed values agree within 3 steps on average and its mean signed error is within 1 step,
/// while a fixed 64-sample reference is more than 5 steps too dark on average (measured: +0.36
/// signed and 1.4 on blocks, against -33.7 and 31.2 for the fixed reference).
#[test]
fn the_converging_reference_is_not_biased_dark_on_glints() {
    let d = Dir::new("reference-glints");
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/glints.toml");
    let run = |size: &str, spp: &str, max: &str, out: &str| {
        ok(&[
            "reference",
            scene,
            "--size",
            size,
            "--spp",
            spp,
            "--max-spp",
            max,
            "-o",
            &d.arg(out),
        ]);
        exr(&d.arg(out))
    };
    let brute = run("192x108", "1024", "1024", "brute.exr");
    let (w, h) = (48usize, 27usize);
    let truth: Vec<[f64; 3]> = (0..w * h)
        .map(|p| {
            let (x, y) = (p % w, p / w);
            let mut sum = [0f64; 3];
            for dy in 0..4 {
                for dx in 0..4 {
                    let q = brute[(4 * y + dy) * 4 * w + 4 * x + dx];
                    for c in 0..3 {
                        sum[c] += f64::from(q[c]) / 16.0;
                    }
                }
            }
            sum.map(|v| display(v as f32))
        })
        .collect();
    // The plane: pixels the brute force does not show black (the sky is black).
    let plane: Vec<bool> = truth.iter().map(|t| t.iter().sum::<f64>() > 0.0).collect();
    let score = |img: &[[f32; 4]]| {
        let (mut signed, mut n) = (0.0, 0.0);
        for p in 0..w * h {
            if plane[p] {
                for c in 0..3 {
                    signed += display(img[p][c]) - truth[p][c];
                    n += 1.0;
                }
            }
        }
        let (mut block, mut blocks) = (0.0, 0.0);
        for by in 0..h / 4 {
            for bx in 0..w / 4 {
                let px: Vec<usize> = (0..16)
                    .map(|k| (4 * by + k / 4) * w + 4 * bx + k % 4)
                    .collect();
                if px.iter().all(|&p| plane[p]) {
                    for c in 0..3 {
                        let mean =
                            |f: &dyn Fn(usize) -> f64| px.iter().map(|&p| f(p)).sum::<f64>() / 16.0;
                        block += (mean(&|p| display(img[p][c])) - mean(&|p| truth[p][c])).abs();
                        blocks += 1.0;
                    }
                }
            }
        }
        (signed / n, block / blocks)
    };
    let converging = score(&run("48x27", "64", "16384", "adaptive.exr"));
    let fixed = score(&run("48x27", "64", "64", "fixed.exr"));
    eprintln!("converging (signed, block): {converging:?}; fixed 64: {fixed:?}");
    assert!(
        converging.0.abs() < 1.0 && converging.1 < 3.0,
        "{converging:?}"
    );
    assert!(
        fixed.0 < -5.0,
        "the fixed reference is not biased dark: {fixed:?}"
    );
}

/// A reference that never converges (tolerance 0), sent `signal` after three seconds, writing to
/// `out` (`extra` arguments added); returns its exit status and stderr.
#[cfg(unix)]
fn interrupted_reference(out: &str, signal: &str, extra: &[&str]) -> (Option<i32>, String) {
    use std::process::{Command, Stdio};
    let child = Command::new(env!("CARGO_BIN_EXE_texel"))
        .args([
            "reference",
            "--size",
            "160x90",
            "--spp",
            "64",
            "--max-spp",
            "1048576",
            "--tolerance",
            "0",
            "-o",
            out,
        ])
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(3000));
    assert!(Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    let result = child.wait_with_output().unwrap();
    (result.status.code(), stderr(&result))
}

/// Whether a PNG file carries the `texel:partial` text chunk.
fn marked_partial(path: &str) -> bool {
    let bytes = file_bytes(path);
    let needle = b"tEXttexel:partial\0interrupted: ";
    bytes.windows(needle.len()).any(|w| w == needle)
}

/// Ctrl-C while a reference converges: it stops at the next pixel row, writes the passes done
/// (each pixel the mean of its whole passes) marked as partial in the file, says so and exits
/// with status 130. An existing file is left as it was unless --keep-partial asks.
#[cfg(unix)]
#[test]
fn an_interrupted_reference_writes_what_it_has() {
    let d = Dir::new("reference-interrupted");
    let out = d.arg("partial.png");
    let map = d.arg("partial-error.exr");
    let (code, err) = interrupted_reference(&out, "-INT", &["--error-map", &map]);
    assert_eq!(code, Some(130), "{err}");
    assert!(
        err.contains("stopping at the next pixel row") && err.contains("marked texel:partial"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(load(&out).size(), (160, 90));
    assert!(marked_partial(&out));
    let exr = file_bytes(&map);
    assert!(exr.windows(13).any(|w| w == b"texel:partial"));
    assert!(temp_files(d.path()).is_empty());
    // SIGTERM over an existing image: left as it was.
    let old = d.write("old.png", "the converged image");
    let (code, err) = interrupted_reference(old.to_str().unwrap(), "-TERM", &[]);
    assert_eq!(code, Some(130), "{err}");
    assert!(
        err.contains("left as it was") && err.contains("--keep-partial"),
        "{err}"
    );
    assert_eq!(file_bytes(&old), b"the converged image");
    // Asked, it is replaced, and marked.
    let (code, err) = interrupted_reference(old.to_str().unwrap(), "-TERM", &["--keep-partial"]);
    assert_eq!(code, Some(130), "{err}");
    assert!(marked_partial(old.to_str().unwrap()), "{err}");
    assert!(temp_files(d.path()).is_empty());
}

/// `--exact`: the ground's every pixel computed, no samples, its error map white (exact), the
/// summary says so; on the lit glossy plane only the background is, and the image is the
/// sampled one.
#[test]
fn exact_reference_of_the_ground_and_of_a_lit_scene() {
    let d = Dir::new("reference-exact");
    let (img, map) = (d.arg("exact.exr"), d.arg("exact-map.png"));
    let out = ok(&[
        "reference",
        "builtin:ground",
        "--size",
        "64x36",
        "--exact",
        "-o",
        &img,
        "--error-map",
        &map,
    ]);
    let err = stderr(&out);
    assert!(err.contains("100.00 % of pixels exact"), "{err}");
    assert!(load(&map)
        .pixels()
        .iter()
        .all(|p| *p == [255, 255, 255, 255]));
    // Agrees with a sampled reference within that reference's own error bars: on at least
    // 95 % of pixels the difference is within its 99 % interval (2.576 standard errors).
    let (sampled, se) = (d.arg("sampled.exr"), d.arg("sampled-se.exr"));
    ok(&[
        "reference",
        "builtin:ground",
        "--size",
        "64x36",
        "--spp",
        "1024",
        "--max-spp",
        "1024",
        "-o",
        &sampled,
        "--error-map",
        &se,
    ]);
    let (a, b, e) = (exr(&img), exr(&sampled), exr(&se));
    let within = a
        .iter()
        .zip(&b)
        .zip(&e)
        .filter(|((x, y), s)| (0..3).all(|k| (x[k] - y[k]).abs() <= 2.576 * s[k] + 1e-6))
        .count();
    let share = within as f64 / a.len() as f64;
    assert!(share >= 0.95, "{share}");
    // `compare` scores against the exact reference by default, and its report says so: every
    // covered pixel exact, no noise floor.
    let report = d.arg("report");
    ok(&[
        "compare",
        "builtin:ground",
        "--size",
        "64x36",
        "--spp",
        "16",
        "--filters",
        "trilinear",
        "--out",
        &report,
    ]);
    let json = std::fs::read_to_string(d.join("report").join("report.json")).unwrap();
    let parsed = texel::quality::Report::from_json(&json).unwrap();
    let e = parsed.reference_error.expect("the reference's figures");
    assert_eq!(e.exact, 1.0);
    assert!(e.noise_floor.is_infinite(), "{e:?}");
    let (lit, plain) = (d.arg("lit.png"), d.arg("plain.png"));
    let args = [
        "reference",
        "builtin:glossy",
        "--size",
        "32x18",
        "--spp",
        "8",
        "--max-spp",
        "8",
    ];
    let out = ok(&[&args[..], &["--exact", "-o", &lit]].concat());
    // Only the sky is exact: every lit pixel is sampled, as without --exact.
    assert!(
        stderr(&out).contains("44.44 % of pixels exact"),
        "{}",
        stderr(&out)
    );
    ok(&[&args[..], &["-o", &plain]].concat());
    assert_eq!(file_bytes(&lit), file_bytes(&plain));
}
