//! Samples per second of the core filters on one thread, on a 1024 x 1024 sRGB RGBA8 texture, for
//! magnified (0.25 texel per pixel), 1:1, 3x, 4x and 64x minified isotropic footprints. The 3x case
//! has a fractional lod (`log2 3 = 1.585`), so trilinear reads two levels there; 4x and 64x sit on
//! integer lods, where trilinear reads one level only.
//!
//! Access is coherent: a 64 x 64 block of "pixels" walks the texture like a rasterizer's tile would,
//! so the numbers are throughput with warm caches, not random-access latency.
//! Run: `cargo bench -p texel-texture --bench sampler`.

#![allow(missing_docs)] // criterion_group! generates undocumented items

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use texel_texture::{
    AddressMode, Cubic, FilterMode, Footprint, Format, Limits, MipmapFilterMode, Sampler,
    SamplerDescriptor, Texture,
};

fn texture() -> Texture {
    Texture::from_fn(1024, 1024, Format::Rgba8Srgb, &Limits::default(), |i, j| {
        let c = (((i / 8) + (j / 8)) % 2) as f32;
        [c, 0.5 * c, i as f32 / 1024.0, 1.0]
    })
    .unwrap()
}

fn footprints(texels_per_pixel: f32) -> Vec<Footprint> {
    let d = texels_per_pixel / 1024.0;
    (0..64 * 64)
        .map(|k| {
            let (x, y) = ((k % 64) as f32 + 0.5, (k / 64) as f32 + 0.5);
            Footprint::isotropic(0.1 + x * d, 0.2 + y * d, d)
        })
        .collect()
}

fn filters() -> Vec<(&'static str, SamplerDescriptor)> {
    let d = |mag, min, mip| SamplerDescriptor {
        mag_filter: mag,
        min_filter: min,
        mipmap_filter: mip,
        ..SamplerDescriptor::default().with_address_mode(AddressMode::Repeat)
    };
    let cubic = FilterMode::Cubic(Cubic::CATMULL_ROM);
    vec![
        (
            "nearest",
            d(
                FilterMode::Nearest,
                FilterMode::Nearest,
                MipmapFilterMode::None,
            ),
        ),
        (
            "bilinear",
            d(
                FilterMode::Linear,
                FilterMode::Linear,
                MipmapFilterMode::None,
            ),
        ),
        ("bicubic", d(cubic, cubic, MipmapFilterMode::None)),
        (
            "mip-nearest",
            d(
                FilterMode::Linear,
                FilterMode::Linear,
                MipmapFilterMode::Nearest,
            ),
        ),
        (
            "trilinear",
            d(
                FilterMode::Linear,
                FilterMode::Linear,
                MipmapFilterMode::Linear,
            ),
        ),
    ]
}

fn bench(c: &mut Criterion) {
    let tex = texture();
    for (label, scale) in [
        ("magnified", 0.25f32),
        ("1to1", 1.0),
        ("minified3x", 3.0),
        ("minified4x", 4.0),
        ("minified64x", 64.0),
    ] {
        let fps = footprints(scale);
        let mut out = vec![[0.0f32; 4]; fps.len()];
        let mut group = c.benchmark_group(format!("sample/{label}"));
        group.throughput(Throughput::Elements(fps.len() as u64));
        for (name, desc) in filters() {
            let s = Sampler::new(desc).unwrap();
            group.bench_with_input(BenchmarkId::from_parameter(name), &fps, |b, fps| {
                b.iter(|| {
                    s.sample_batch(&tex, black_box(fps), &mut out);
                    black_box(&out);
                })
            });
        }
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
