//! Lit scenes with materials through the command line: the glossy normal-mapped plane.

use texel::quality::psnr;

use crate::util::*;

/// Toksvig's and LEAN's specular antialiasing are closer to the reference (which shades every
/// sub-sample with exact level-0 normals) than plain filtered normals, for trilinear and aniso16;
/// LEAN with aniso16 by the 6 dB (measured at this size: trilinear none 14.79, Toksvig
/// 19.37, LEAN 20.12 dB; aniso16 15.44, 21.63, 22.96 dB; LEAN was 4.7 dB above none before its
/// lobe took the slopes' covariance and the GGX-Gaussian mixture shape).
#[test]
fn toksvig_beats_plain_filtered_normals_against_the_reference() {
    let d = Dir::new("glossy");
    let size = ["--size", "320x180"];
    ok(&[
        "reference",
        "builtin:glossy",
        size[0],
        size[1],
        "--spp",
        "64",
        "--max-spp",
        "64",
        "-o",
        &d.arg("ref.png"),
    ]);
    let reference = load(d.join("ref.png"));
    for filter in ["trilinear", "aniso16"] {
        let mut db = Vec::new();
        for aa in ["none", "toksvig", "lean"] {
            let name = format!("{filter}-{aa}.png");
            ok(&[
                "render",
                "builtin:glossy",
                size[0],
                size[1],
                "--filter",
                filter,
                "--specular-aa",
                aa,
                "-o",
                &d.arg(&name),
            ]);
            db.push(psnr(&load(d.join(&name)), &reference, None).unwrap());
        }
        eprintln!(
            "{filter}: none {:.2} dB, toksvig {:.2} dB, lean {:.2} dB",
            db[0], db[1], db[2]
        );
        assert!(
            db[1] >= db[0] + 2.0 && db[2] >= db[0] + 2.0,
            "{filter}: {db:?}"
        );
        if filter == "aniso16" {
            assert!(db[2] >= db[0] + 6.0, "{filter}: {db:?}");
        }
    }
}

#[test]
fn lit_scenes_are_refused_where_a_path_cannot_light_them() {
    // The GPU path has no lighting: a clear refusal, not an unlit image.
    if !crate::gpu::have_adapter() {
        return;
    }
    let d = Dir::new("glossy-gpu");
    let out = texel(&[
        "render",
        "builtin:glossy",
        "--gpu",
        "--size",
        "64x32",
        "-o",
        &d.arg("g.png"),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("texel: error: the GPU path does not support materials"),
        "{err}"
    );
    assert!(!d.join("g.png").exists());
}

/// `compare --orbit`: the report gains PSNR over the orbit and flicker beyond the reference's
/// per filter; nearest, which aliases, flickers far more than trilinear (measured 50.0 against
/// 23.5 at this size).
#[test]
fn an_orbit_reports_flicker_and_aliasing_flickers_most() {
    let d = Dir::new("orbit");
    ok(&[
        "compare",
        "builtin:glossy",
        "--size",
        "160x90",
        "--filters",
        "nearest,trilinear",
        "--spp",
        "16",
        "--orbit",
        "3",
        "--out",
        &d.arg("report"),
    ]);
    let json = std::fs::read_to_string(d.join("report/report.json")).unwrap();
    let report = texel::quality::Report::from_json(&json).unwrap();
    let orbit = report.orbit.as_ref().expect("an orbit in the report");
    assert_eq!((orbit.frames, orbit.step_deg), (3, 0.1));
    assert!(orbit.reference_flicker > 0.0);
    let flicker: Vec<f64> = report.rows.iter().map(|r| r.flicker.unwrap()).collect();
    assert!(flicker.iter().all(|f| f.is_finite() && *f >= 0.0));
    assert!(flicker[0] > 1.5 * flicker[1], "{flicker:?}");
    for r in &report.rows {
        let p = r.psnr_orbit.unwrap();
        assert!(
            p.is_finite() && (p - r.psnr_all).abs() < 3.0,
            "{}: {p}",
            r.name
        );
    }
    fails(
        &["compare", "--orbit", "1", "--out", &d.arg("x")],
        2,
        &["--orbit"],
    );
    fails(
        &[
            "compare",
            "--orbit",
            "3",
            "--orbit-step",
            "NaN",
            "--out",
            &d.arg("x"),
        ],
        2,
        &["outside 0 to 10"],
    );
}

/// `--shading-samples`: adaptive shading supersampling brings LEAN's aniso16 orbit closer to the
/// reference and steadier, on the glossy plane where near bumps are a few pixels wide (measured
/// at this size: PSNR 20.19 -> 21.09 dB, flicker 13.46 -> 11.62); values outside 1..=8 are refused.
#[test]
fn shading_sub_samples_lower_lean_flicker_on_the_glossy_orbit() {
    let d = Dir::new("shading-samples");
    let run = |samples: &str| {
        let out = d.arg(&format!("report-{samples}"));
        ok(&[
            "compare",
            "builtin:glossy",
            "--size",
            "320x180",
            "--filters",
            "aniso16",
            "--spp",
            "64",
            "--orbit",
            "3",
            "--specular-aa",
            "lean",
            "--shading-samples",
            samples,
            "--out",
            &out,
        ]);
        let json =
            std::fs::read_to_string(d.join(&format!("report-{samples}/report.json"))).unwrap();
        let report = texel::quality::Report::from_json(&json).unwrap();
        let row = &report.rows[0];
        (row.psnr_all, row.flicker.unwrap())
    };
    let (one, four) = (run("1"), run("4"));
    eprintln!("one sample: {one:?}, up to 4 x 4: {four:?}");
    assert!(four.0 > one.0 + 0.5, "{one:?} vs {four:?}");
    assert!(four.1 < 0.93 * one.1, "{one:?} vs {four:?}");
    for bad in ["0", "9", "x"] {
        fails(
            &[
                "render",
                "builtin:glossy",
                "--shading-samples",
                bad,
                "-o",
                &d.arg("x.png"),
            ],
            2,
            &["--shading-samples"],
        );
    }
    assert!(!d.join("x.png").exists());
}

/// The brick wall: every `--displacement` is scored against one truth (the finely tessellated,
/// level-0-displaced wall), so the reference is the same image whatever the method; the methods
/// differ from each other; bad edge lengths are refused.
#[test]
fn every_displacement_is_scored_against_the_same_displaced_reference() {
    let d = Dir::new("bricks");
    let mut references = Vec::new();
    let mut images = Vec::new();
    for method in ["none", "bump", "pom", "tessellate"] {
        let out = d.arg(method);
        ok(&[
            "compare",
            "builtin:bricks",
            "--size",
            "96x54",
            "--filters",
            "trilinear",
            "--spp",
            "4",
            "--displacement",
            method,
            "--out",
            &out,
        ]);
        references.push(std::fs::read(d.join(&format!("{method}/reference.png"))).unwrap());
        images.push(load(d.join(&format!("{method}/trilinear.png"))));
    }
    assert!(references.windows(2).all(|w| w[0] == w[1]));
    for i in 0..images.len() {
        for j in 0..i {
            assert!(
                psnr(&images[i], &images[j], None).unwrap() < 60.0,
                "{i} {j}"
            );
        }
    }
    fails(
        &[
            "render",
            "builtin:bricks",
            "--edge-px",
            "0",
            "-o",
            &d.arg("x.png"),
        ],
        2,
        &["outside 0.25 to 256"],
    );
}

/// The layered terrain: both `--layer-order`s are scored against one reference (the layers
/// blended per sub-sample from level-0 reads); blending before filtering comes closer to it
/// under anisotropic filtering (measured 8.2 dB at 640x360 with 64 samples, 7.2 dB at this size;
/// the mask and heights vary under the distant pixels, where filtering then blending mixes them
/// wrongly); a bad order is refused.
#[test]
fn both_layer_orders_are_scored_against_the_same_reference() {
    let d = Dir::new("terrain");
    let mut references = Vec::new();
    let mut scores = Vec::new();
    for order in ["filter-then-blend", "blend-then-filter"] {
        let out = d.arg(order);
        ok(&[
            "compare",
            "builtin:terrain",
            "--size",
            "240x135",
            "--filters",
            "aniso16",
            "--spp",
            "16",
            "--layer-order",
            order,
            "--out",
            &out,
        ]);
        let reference = load(d.join(&format!("{order}/reference.png")));
        let image = load(d.join(&format!("{order}/aniso16.png")));
        scores.push(psnr(&image, &reference, None).unwrap());
        references.push(std::fs::read(d.join(&format!("{order}/reference.png"))).unwrap());
    }
    eprintln!(
        "aniso16: filter then blend {:.2} dB, blend then filter {:.2} dB",
        scores[0], scores[1]
    );
    assert!(references[0] == references[1], "the references differ");
    assert!(scores[1] > scores[0] + 2.0, "{scores:?}");
    fails(
        &[
            "render",
            "builtin:terrain",
            "--layer-order",
            "sideways",
            "-o",
            &d.arg("x.png"),
        ],
        2,
        &["sideways"],
    );
}
