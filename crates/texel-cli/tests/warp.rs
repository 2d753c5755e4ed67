//! `texel warp`: identity, size, and shrinking a fine checkerboard without aliasing.

use texel::quality::Image8;

use crate::util::*;

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
