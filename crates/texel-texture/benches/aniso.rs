//! Benchmarks for every filter at anisotropy ratios 1, 4, 16 and 64 (samples per second, texels
//! read per sample), and build time and memory of the mip pyramid, the ripmap and the summed-area
//! table of a 2048x2048 texture.
//!
//! `cargo bench -p texel-texture --bench aniso` (add `-- --quick` for a fast pass). Texels per
//! sample and bytes are printed as `TABLE` lines before criterion's timings.

// criterion's macros generate undocumented functions.
#![allow(missing_docs)]

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use glam::Vec2;
use texel_texture::{
    AddressMode, ColorSpace, Cubic, Filter, FilterMode, Footprint, Limits, MipmapFilterMode,
    Ripmap, Sampler, SamplerDescriptor, SummedAreaTable, Texture,
};

const SIZE: u32 = 2048;
const BATCH: usize = 4096;

use texel_texture::base::rng::SplitMix64 as Rng;

fn texels() -> Vec<[u8; 4]> {
    let mut rng = Rng::new(42);
    (0..SIZE * SIZE)
        .map(|_| {
            let b = (rng.next_f32() * 255.0) as u8;
            [b, b.wrapping_mul(3), b.wrapping_add(90), 255]
        })
        .collect()
}

/// `BATCH` footprints: minor axis 2 texels, major `2 * ratio`, random angle and position.
fn footprints(ratio: f32) -> Vec<Footprint> {
    let mut rng = Rng::new(7 + ratio as u64);
    let s = SIZE as f32;
    (0..BATCH)
        .map(|_| {
            let a = rng.next_f32() * std::f32::consts::TAU;
            let d = Vec2::new(a.cos(), a.sin());
            let (px, py) = (d * 2.0 * ratio, d.perp() * 2.0);
            Footprint {
                u: rng.next_f32(),
                v: rng.next_f32(),
                dudx: px.x / s,
                dvdx: px.y / s,
                dudy: py.x / s,
                dvdy: py.y / s,
            }
        })
        .collect()
}

fn filters() -> Vec<(&'static str, SamplerDescriptor)> {
    let lab = |m| {
        Filter::from_lab_mode(m)
            .map(SamplerDescriptor::from)
            .unwrap()
    };
    vec![
        ("nearest", lab(1)),
        ("bilinear", lab(2)),
        ("mip_nearest", lab(3)),
        ("trilinear", lab(4)),
        (
            "bicubic_trilinear",
            SamplerDescriptor {
                mag_filter: FilterMode::Cubic(Cubic::CATMULL_ROM),
                min_filter: FilterMode::Cubic(Cubic::CATMULL_ROM),
                mipmap_filter: MipmapFilterMode::Linear,
                ..Default::default()
            },
        ),
        ("aniso2", lab(5)),
        ("aniso4", lab(6)),
        ("aniso8", lab(7)),
        ("aniso16", lab(8)),
        ("ewa", SamplerDescriptor::minification(FilterMode::Ewa)),
        (
            "ripmap",
            SamplerDescriptor::minification(FilterMode::Ripmap),
        ),
        (
            "summed_area",
            SamplerDescriptor::minification(FilterMode::SummedArea),
        ),
    ]
}

fn sampling(c: &mut Criterion) {
    let tex =
        Texture::from_rgba8(SIZE, SIZE, texels(), ColorSpace::Srgb, &Limits::default()).unwrap();
    let mut group = c.benchmark_group("sample");
    group.throughput(Throughput::Elements(BATCH as u64));
    for ratio in [1.0f32, 4.0, 16.0, 64.0] {
        let fps = footprints(ratio);
        for (name, desc) in filters() {
            let s = Sampler::new(desc.with_address_mode(AddressMode::Repeat)).unwrap();
            tex.build_structures(&s).unwrap();
            let reads: u64 = fps
                .iter()
                .map(|f| u64::from(s.sample_counted(&tex, f).1))
                .sum();
            println!(
                "TABLE texels_per_sample {name} ratio {ratio} {:.2}",
                reads as f64 / BATCH as f64
            );
            let mut out = vec![[0.0f32; 4]; BATCH];
            group.bench_function(format!("{name}/ratio{ratio}"), |b| {
                b.iter(|| {
                    s.sample_batch(&tex, black_box(&fps), &mut out);
                    black_box(&out);
                })
            });
        }
    }
    group.finish();
}

fn building(c: &mut Criterion) {
    let data = texels();
    let limits = Limits::default();
    let tex = Texture::from_rgba8(SIZE, SIZE, data.clone(), ColorSpace::Srgb, &limits).unwrap();
    println!("TABLE bytes pyramid {}", tex.pyramid_bytes());
    println!(
        "TABLE bytes ripmap {}",
        Ripmap::bytes_for(SIZE, SIZE, tex.format()).unwrap()
    );
    println!(
        "TABLE bytes summed_area {}",
        SummedAreaTable::bytes_for(SIZE, SIZE).unwrap()
    );
    let mut group = c.benchmark_group("build2048");
    group.sample_size(10);
    group.bench_function("pyramid", |b| {
        b.iter_batched(
            || data.clone(),
            |d| Texture::from_rgba8(SIZE, SIZE, d, ColorSpace::Srgb, &limits).unwrap(),
            BatchSize::LargeInput,
        )
    });
    group.bench_function("ripmap", |b| b.iter(|| Ripmap::build(&tex).unwrap()));
    group.bench_function("summed_area", |b| {
        b.iter(|| SummedAreaTable::build(&tex).unwrap())
    });
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1));
    targets = building, sampling
}
criterion_main!(benches);
