//! Samples per second of the core filters on one thread, on a 1024 x 1024 sRGB RGBA8 texture, for
//! magnified (0.25 texel per pixel), 1:1, 3x, 4x and 64x minified isotropic footprints. The 3x case
//! has a fractional lod (`log2 3 = 1.585`), so trilinear reads two levels there; 4x and 64x sit on
//! integer lods, where trilinear reads one level only.
//!
//! Access is coherent: a 64 x 64 block of "pixels" walks the texture like a rasterizer's tile would,
//! so the numbers are throughput with warm caches, not random-access latency.
//! Run: `cargo bench -p texel-texture --bench sampler`.
//!
//! The `bound/*` group measures what the 8-bit path's design allows: the same samplers on a float
//! copy of the texture (no decode), and the texel loads, table decodes and blends of the 1:1
//! bilinear walk alone, with every coordinate computed beforehand (nothing a sampler could skip).
//!
//! The `fixed8/*` group compares, on a unorm copy of the texture, the exact `f32` path
//! (`sample_batch`) with the GPU-style fixed-point one (a sampler bound for `SpanKind::Fixed8`, unorm8 codes out).
//! The batched rows (`sample_batch`, the fixed-point span) run the best instruction-set copy
//! the CPU has (`texel_texture::dispatch`, as in the rasterizer); the
//! `bound/decode-and-blend-only/bilinear` loop is baseline code.

#![allow(missing_docs)] // criterion_group! generates undocumented items

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::Vec4;
use texel_texture::base::color::{srgb_table, unorm8_table};
use texel_texture::{
    AddressMode, Cubic, FilterMode, Footprint, Format, Lanes, Limits, MipmapFilterMode, Sampler,
    SamplerDescriptor, SpanKind, Texture, Wants,
};

/// The benchmark texture's texel `(i, j)` in linear RGBA.
fn pattern(i: u32, j: u32) -> [f32; 4] {
    let c = (((i / 8) + (j / 8)) % 2) as f32;
    [c, 0.5 * c, i as f32 / 1024.0, 1.0]
}

fn texture() -> Texture {
    Texture::from_fn(1024, 1024, Format::Rgba8Srgb, &Limits::default(), pattern).unwrap()
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

/// Lower bounds for the 8-bit path (see the module docs).
fn bound(c: &mut Criterion) {
    let f32_tex =
        Texture::from_fn(1024, 1024, Format::Rgba32Float, &Limits::default(), pattern).unwrap();
    let mut group = c.benchmark_group("bound");
    for (label, scale, name) in [
        ("f32-texture-1to1", 1.0f32, "bilinear"),
        ("f32-texture-minified3x", 3.0, "trilinear"),
    ] {
        let fps = footprints(scale);
        let mut out = vec![[0.0f32; 4]; fps.len()];
        let (_, desc) = filters().into_iter().find(|f| f.0 == name).unwrap();
        let s = Sampler::new(desc).unwrap();
        group.throughput(Throughput::Elements(fps.len() as u64));
        group.bench_function(format!("{label}/{name}"), |b| {
            b.iter(|| {
                s.sample_batch(&f32_tex, black_box(&fps), &mut out);
                black_box(&out);
            })
        });
    }
    // The 1:1 bilinear walk's texels as the 8-bit path stores them (sRGB bytes), its top-left
    // indices and fractions computed beforehand: per sample two 2-texel row reads, 16 table loads
    // and three blends, as `batch`'s texel stage does for a sample inside the level.
    let w = 1024usize;
    let texels: Vec<[u8; 4]> = (0..w * w)
        .map(|k| {
            let t = pattern((k % w) as u32, (k / w) as u32);
            [0, 1, 2, 3].map(|c| {
                let x = if c < 3 {
                    texel_texture::base::color::linear_to_srgb(t[c])
                } else {
                    t[c]
                };
                texel_texture::base::color::unorm8(x)
            })
        })
        .collect();
    let quads: Vec<(usize, f32, f32)> = footprints(1.0)
        .iter()
        .map(|f| {
            let (x, y) = (f.u * 1024.0 - 0.5, f.v * 1024.0 - 0.5);
            let (i, j) = (x.floor(), y.floor());
            (j as usize * w + i as usize, x - i, y - j)
        })
        .collect();
    let (table, alpha) = (srgb_table(), unorm8_table());
    let decode = |t: [u8; 4]| {
        Vec4::new(
            table[t[0] as usize],
            table[t[1] as usize],
            table[t[2] as usize],
            alpha[t[3] as usize],
        )
    };
    let mut out = vec![[0.0f32; 4]; quads.len()];
    group.throughput(Throughput::Elements(quads.len() as u64));
    group.bench_function("decode-and-blend-only/bilinear", |b| {
        b.iter(|| {
            for (o, &(k, a, bb)) in out.iter_mut().zip(black_box(&quads)) {
                let (r0, r1) = (&texels[k..k + 2], &texels[k + w..k + w + 2]);
                let (t00, t10, t01, t11) =
                    (decode(r0[0]), decode(r0[1]), decode(r1[0]), decode(r1[1]));
                let top = t00 + (t10 - t00) * a;
                let bottom = t01 + (t11 - t01) * a;
                *o = (top + (bottom - top) * bb).to_array();
            }
            black_box(&out);
        })
    });
    group.finish();
}

/// Exact `f32` against fixed-point filtering of a unorm8 texture (see the module docs).
fn fixed8(c: &mut Criterion) {
    let unorm =
        Texture::from_fn(1024, 1024, Format::Rgba8Unorm, &Limits::default(), pattern).unwrap();
    let mut group = c.benchmark_group("fixed8");
    for (label, scale, name) in [
        ("1to1", 1.0f32, "bilinear"),
        ("minified3x", 3.0, "mip-nearest"),
        ("minified3x", 3.0, "trilinear"),
    ] {
        let fps = footprints(scale);
        let (_, desc) = filters().into_iter().find(|f| f.0 == name).unwrap();
        let s = Sampler::new(desc).unwrap();
        group.throughput(Throughput::Elements(fps.len() as u64));
        let mut out = vec![[0.0f32; 4]; fps.len()];
        group.bench_function(format!("{label}/{name}/exact"), |b| {
            b.iter(|| {
                s.sample_batch(&unorm, black_box(&fps), &mut out);
                black_box(&out);
            })
        });
        let mut codes = vec![[0u8; 4]; fps.len()];
        let wants = Wants {
            stored_bytes: false,
            fixed8: true,
        };
        let bound = s.bind(&unorm, wants);
        assert_eq!(bound.kind(), SpanKind::Fixed8);
        let lanes = Lanes::detect();
        group.bench_function(format!("{label}/{name}/gpu"), |b| {
            b.iter(|| {
                bound.sample_span(lanes, black_box(&fps), &mut [], &mut codes);
                black_box(&codes);
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench, bound, fixed8);
criterion_main!(benches);
