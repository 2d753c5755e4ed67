//! Frame-time benchmarks: the ground scene (`scenes/ground.toml`) at 1280 x 720 with the
//! four core filters, on 1 and 2 threads; triangle throughput on a 100k-triangle mesh.
//!
//! Run: `CARGO_TARGET_DIR=/work/target-shared cargo bench -p texel-raster --bench frame`.

// criterion_group! generates an undocumented public function.
#![allow(missing_docs)]

#[path = "../tests/common/mod.rs"]
mod common;

use std::hint::black_box;
use std::time::Duration;

use common::{lab_sampler, screen_grid, Ground};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::Mat4;
use texel_raster::{render, DrawCall, RenderSettings};
use texel_texture::Sampler;

/// The four core filters this bench times: the lab's modes 1-4 (nearest, bilinear, mip-nearest,
/// trilinear). The anisotropic filters (modes 5-8) and EWA have no rows here; their frame times
/// come from `texel bench` (docs/guide/measuring.md) and their per-sample throughput from
/// `cargo bench -p texel-texture --bench aniso`.
fn samplers() -> Vec<(&'static str, Sampler)> {
    vec![
        ("nearest", lab_sampler(1)),
        ("bilinear", lab_sampler(2)),
        ("mip_nearest", lab_sampler(3)),
        ("trilinear", lab_sampler(4)),
    ]
}

fn ground(c: &mut Criterion) {
    let (w, h) = (1280, 720);
    let scene = Ground::new(w, h);
    let mut group = c.benchmark_group("ground_1280x720");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(4));
    for (name, sampler) in samplers() {
        let draw = scene.draw(&sampler);
        for threads in [1, 2] {
            let settings = RenderSettings {
                threads: Some(threads),
                ..RenderSettings::new(w, h)
            };
            group.bench_with_input(BenchmarkId::new(name, threads), &settings, |b, s| {
                b.iter(|| black_box(render(s, &[draw]).unwrap()))
            });
        }
    }
    group.finish();
}

fn mesh(c: &mut Criterion) {
    let (w, h) = (1280, 720);
    // 224 x 224 cells, two triangles each: 100 352 triangles over the whole frame (~9 px each).
    let (vertices, triangles, texture) = screen_grid(w, h, 224, 224);
    let sampler = lab_sampler(4);
    let draw = DrawCall {
        vertices: &vertices,
        triangles: &triangles,
        texture: &texture,
        sampler: &sampler,
        clip_from_world: Mat4::IDENTITY,
        material: None,
        uv_mapping: None,
    };
    let mut group = c.benchmark_group("mesh_100k_64x64_trilinear");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(4))
        .throughput(Throughput::Elements(triangles.len() as u64));
    for threads in [1, 2] {
        let settings = RenderSettings {
            threads: Some(threads),
            ..RenderSettings::new(w, h)
        };
        group.bench_with_input(BenchmarkId::from_parameter(threads), &settings, |b, s| {
            b.iter(|| black_box(render(s, &[draw]).unwrap()))
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default();
    targets = ground, mesh
}
criterion_main!(benches);
