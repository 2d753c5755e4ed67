//! Atomic outputs: failed writes leave nothing behind.

use crate::util::*;

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
        &[
            "reference",
            "--size",
            "32x18",
            "--spp",
            "1",
            "--max-spp",
            "1",
            "-o",
            &x,
        ],
        1,
        &["cannot write", &x],
    );
    let src = grey_png(&d, "src.png");
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
        &compare_extra(&format!("gpu={}", d.arg("missing.png")), &d.arg("cmp")),
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

/// The linear float colour of an OpenEXR file.
fn load_exr(path: &std::path::Path) -> (u32, u32, Vec<[f32; 4]>) {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("cannot load {}: {e}", path.display()))
        .to_rgba32f();
    let px = img.pixels().map(|p| p.0).collect();
    (img.width(), img.height(), px)
}

/// An output named `.exr` (any case) is OpenEXR holding the frame's linear colour unclamped: the
/// glossy plane's highlight is above 1, and encoding the floats gives the PNG's bytes exactly.
#[test]
fn exr_outputs_keep_the_linear_colour_unclamped() {
    let d = Dir::new("exr");
    let scene = ["builtin:glossy", "--size", "96x54"];
    for (cmd, extra) in [
        ("render", &["--filter", "aniso16"][..]),
        ("reference", &["--spp", "4", "--max-spp", "4"][..]),
    ] {
        let exr = d.arg(&format!("{cmd}.EXR"));
        let png = d.arg(&format!("{cmd}.png"));
        for out in [&exr, &png] {
            let mut args = vec![cmd];
            args.extend_from_slice(&scene);
            args.extend_from_slice(extra);
            args.extend_from_slice(&["-o", out]);
            ok(&args);
        }
        assert_eq!(
            &file_bytes(&exr)[..4],
            &[0x76, 0x2f, 0x31, 0x01],
            "OpenEXR magic"
        );
        let (w, h, px) = load_exr(std::path::Path::new(&exr));
        assert_eq!((w, h), (96, 54));
        let brightest = px
            .iter()
            .map(|p| p[0].max(p[1]).max(p[2]))
            .fold(0.0, f32::max);
        assert!(brightest > 1.5, "{cmd}: highlight {brightest}");
        let encoded =
            texel::quality::Image8::from_linear(w, h, &px, texel::quality::Encoding::Srgb).unwrap();
        assert_eq!(encoded.pixels(), load(&png).pixels(), "{cmd}");
    }
}
