//! `texel reference`: size and reproducibility.

use crate::util::*;

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
