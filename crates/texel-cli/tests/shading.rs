//! Lit scenes with materials through the command line: the glossy normal-mapped plane.

use texel_quality::psnr;

use crate::util::*;

/// Toksvig's and LEAN's specular antialiasing are closer to the reference (which shades every
/// sub-sample with exact level-0 normals) than plain filtered normals, for trilinear and aniso16
/// (measured 3.5-4.7 dB closer at this size).
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
