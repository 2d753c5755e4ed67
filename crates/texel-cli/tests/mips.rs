//! `texel mips`: every level and the chain.

use texel::quality::Image8;

use crate::util::*;

#[test]
fn mips_writes_every_level_and_the_chain() {
    let d = Dir::new("mips");
    // 16 x 8 of uniform 2x2 blocks: level 1 is exactly the block colours (raw bytes).
    let block = |x: u32, y: u32| [(x / 2 * 30) as u8, (y / 2 * 60) as u8, 200, 255];
    let src = Image8::from_fn(16, 8, block).unwrap();
    let out = raw_mips(&d, &src, "tex.png", "mips");
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
    expected.push(texel_io::OUTPUT_MARKER.to_string());
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
    let out = raw_mips(&d, &odd, "odd.png", "odd");
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

/// Write `image` to `d/file` and run `texel mips` on it with `--color raw` into `d/out`; returns
/// the output directory.
fn raw_mips(d: &Dir, image: &Image8, file: &str, out: &str) -> std::path::PathBuf {
    let input = d.join(file);
    image.write_png(&input).unwrap();
    let dir = d.join(out);
    ok(&[
        "mips",
        &input.to_string_lossy(),
        "--color",
        "raw",
        "--out",
        &dir.to_string_lossy(),
    ]);
    dir
}
