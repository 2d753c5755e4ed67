//! PSNR and SSIM on a 1280x720 frame (the ground scene's size).
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion};
use texel_quality::{psnr, ssim, Image8, Mask};

fn frames() -> (Image8, Image8, Mask) {
    let (w, h) = (1280, 720);
    let a = Image8::from_fn(w, h, |x, y| {
        let v = ((x / 16 + y / 16) % 2 * 255) as u8;
        [v, v, v, 255]
    })
    .unwrap();
    let b = Image8::from_fn(w, h, |x, y| {
        let v = ((x * 7 + y * 13) % 256) as u8;
        [v, v / 2, 255 - v, 255]
    })
    .unwrap();
    let m = Mask::from_fn(w, h, |_, y| y >= 300).unwrap();
    (a, b, m)
}

fn bench(c: &mut Criterion) {
    let (a, b, m) = frames();
    c.bench_function("psnr 1280x720 masked", |bch| {
        bch.iter(|| psnr(&a, &b, Some(&m)).unwrap())
    });
    c.bench_function("ssim 1280x720 masked", |bch| {
        bch.iter(|| ssim(&a, &b, Some(&m)).unwrap())
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);
