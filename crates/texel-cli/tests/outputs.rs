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
        &["reference", "--size", "32x18", "--spp", "1", "-o", &x],
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
