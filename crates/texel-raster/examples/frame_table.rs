//! Print the frame-time table of docs/benchmarks.md: the ground scene at 1280 x 720 per
//! filter and thread count, the 100k-triangle mesh, and the 16 x 16 reference; min and median of N runs (the min is the
//! least-disturbed estimate on a shared machine; criterion's `benches/frame.rs` measures the same
//! renders).
//!
//! `cargo run --release -p texel-raster --example frame_table -- [RUNS]`

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use common::{lab_sampler, screen_grid, Ground};
use glam::Mat4;
use texel_raster::{render, render_reference, DrawCall, RenderSettings};

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

/// `(min, median)` of rendering `draw` at `w x h` on 1 thread, then on 2.
fn per_thread_count(runs: usize, w: u32, h: u32, draw: DrawCall) -> Vec<(f64, f64)> {
    [1, 2]
        .iter()
        .map(|&threads| {
            let s = RenderSettings {
                threads: Some(threads),
                ..RenderSettings::new(w, h)
            };
            let (min, med) = time(runs, || {
                render(&s, &[draw]).unwrap();
            });
            (min, med)
        })
        .collect()
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
        let cells: Vec<String> = per_thread_count(runs, w, h, draw)
            .iter()
            .map(|(min, med)| format!("{min:.1} / {med:.1}"))
            .collect();
        println!("| ground 1280x720, {name} | {} | {} |", cells[0], cells[1]);
    }
    // 100k-triangle mesh, 64x64 texture.
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
    let cells: Vec<String> = per_thread_count(runs, w, h, draw)
        .iter()
        .map(|(min, med)| {
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
