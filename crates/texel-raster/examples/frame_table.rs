//! Print the README's frame-time table: the ground scene at 1280 x 720 per filter and thread count,
//! the 100k-triangle mesh, and the 16 x 16 reference; min and median of N runs (the min is the
//! least-disturbed estimate on a shared machine; criterion's `benches/frame.rs` measures the same
//! renders).
//!
//! `cargo run --release -p texel-raster --example frame_table -- [RUNS]`

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use common::{lab_sampler, screen_vertex, Ground};
use glam::Mat4;
use texel_raster::{render, render_reference, DrawCall, RenderSettings};
use texel_texture::{Format, Limits, Texture};

/// (min, median) in milliseconds of `runs` calls of `f`.
fn time(runs: usize, mut f: impl FnMut()) -> (f64, f64) {
    f(); // warm up
    let mut t: Vec<f64> = (0..runs)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(|a, b| a.partial_cmp(b).unwrap());
    (t[0], t[runs / 2])
}

fn main() {
    let runs: usize = std::env::args()
        .nth(1)
        .map_or(20, |s| s.parse().expect("a number"));
    let (w, h) = (1280, 720);
    let scene = Ground::new(w, h);
    println!("| render | 1 thread min / median (ms) | 2 threads min / median (ms) |");
    println!("|---|---|---|");
    for (name, mode) in [
        ("nearest", 1),
        ("bilinear", 2),
        ("mip nearest", 3),
        ("trilinear", 4),
    ] {
        let sampler = lab_sampler(mode);
        let draw = scene.draw(&sampler);
        let cells: Vec<String> = [1, 2]
            .iter()
            .map(|&threads| {
                let s = RenderSettings {
                    threads: Some(threads),
                    ..RenderSettings::new(w, h)
                };
                let (min, med) = time(runs, || {
                    render(&s, &[draw]).unwrap();
                });
                format!("{min:.1} / {med:.1}")
            })
            .collect();
        println!("| ground 1280x720, {name} | {} | {} |", cells[0], cells[1]);
    }
    // 100k-triangle mesh, 64x64 texture.
    let (nx, ny) = (224u32, 224u32);
    let vertices: Vec<_> = (0..=ny)
        .flat_map(|b| {
            (0..=nx).map(move |a| {
                screen_vertex(
                    f64::from(a) * f64::from(w) / f64::from(nx),
                    f64::from(b) * f64::from(h) / f64::from(ny),
                    w,
                    h,
                )
            })
        })
        .collect();
    let triangles: Vec<[u32; 3]> = (0..ny)
        .flat_map(|b| {
            (0..nx).flat_map(move |a| {
                let k = b * (nx + 1) + a;
                [[k, k + 1, k + nx + 2], [k, k + nx + 2, k + nx + 1]]
            })
        })
        .collect();
    let texture = Texture::from_fn(64, 64, Format::Rgba8Srgb, &Limits::default(), |i, j| {
        [i as f32 / 63.0, j as f32 / 63.0, 0.5, 1.0]
    })
    .unwrap();
    let sampler = lab_sampler(4);
    let draw = DrawCall {
        vertices: &vertices,
        triangles: &triangles,
        texture: &texture,
        sampler: &sampler,
        clip_from_world: Mat4::IDENTITY,
    };
    let cells: Vec<String> = [1, 2]
        .iter()
        .map(|&threads| {
            let s = RenderSettings {
                threads: Some(threads),
                ..RenderSettings::new(w, h)
            };
            let (min, med) = time(runs, || {
                render(&s, &[draw]).unwrap();
            });
            let mtri = triangles.len() as f64 / (min * 1e-3) / 1e6;
            format!("{min:.1} / {med:.1} ({mtri:.2} M tri/s)")
        })
        .collect();
    println!(
        "| mesh {} triangles, 64x64 trilinear, 1280x720 | {} | {} |",
        triangles.len(),
        cells[0],
        cells[1]
    );
    let sampler = lab_sampler(4);
    let cells: Vec<String> = [1, 2]
        .iter()
        .map(|&threads| {
            let s = RenderSettings {
                threads: Some(threads),
                ..RenderSettings::new(w, h)
            };
            let start = Instant::now();
            render_reference(&s, &[scene.draw(&sampler)], 16, 1, None).unwrap();
            format!("{:.0} (1 run)", start.elapsed().as_secs_f64() * 1e3)
        })
        .collect();
    println!(
        "| reference 16x16 spp, ground 1280x720 | {} | {} |",
        cells[0], cells[1]
    );
}
