//! Render the ground scene (`scenes/ground.toml`) with several filters, debug views and the
//! reference renderer, write PNGs and print the time each took.
//!
//! `cargo run --release -p texel-raster --example ground -- OUT_DIR [WIDTH HEIGHT SPP_SIDE]`

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use common::{lab_sampler, Ground};
use texel_raster::{render, render_reference, Frame, Perspective, RenderSettings, View};

fn save(frame: &Frame, path: &std::path::Path) {
    image::save_buffer(
        path,
        &frame.to_srgb8(),
        frame.width,
        frame.height,
        image::ExtendedColorType::Rgba8,
    )
    .expect("write png");
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let out = std::path::PathBuf::from(args.get(1).map_or("ground-out", String::as_str));
    let num = |k: usize, d: u32| args.get(k).map_or(d, |s| s.parse().expect("a number"));
    let (w, h, spp) = (num(2, 1280), num(3, 720), num(4, 16));
    std::fs::create_dir_all(&out).expect("create output directory");
    let scene = Ground::new(w, h);
    let base = RenderSettings::new(w, h);
    let runs: Vec<(&str, u8, RenderSettings)> = vec![
        ("nearest", 1, base),
        ("bilinear", 2, base),
        ("mip_nearest", 3, base),
        ("trilinear", 4, base),
        (
            "affine",
            4,
            RenderSettings {
                perspective: Perspective::Affine,
                ..base
            },
        ),
        (
            "view_uv",
            4,
            RenderSettings {
                view: View::Uv,
                ..base
            },
        ),
        (
            "view_mip",
            4,
            RenderSettings {
                view: View::Mip,
                ..base
            },
        ),
        (
            "view_lod",
            4,
            RenderSettings {
                view: View::Lod,
                ..base
            },
        ),
        (
            "view_aniso",
            4,
            RenderSettings {
                view: View::Aniso,
                ..base
            },
        ),
        (
            "view_fetches",
            4,
            RenderSettings {
                view: View::Fetches,
                ..base
            },
        ),
        (
            "view_barycentric",
            4,
            RenderSettings {
                view: View::Barycentric,
                ..base
            },
        ),
    ];
    for (name, mode, settings) in runs {
        let sampler = lab_sampler(mode);
        let t = Instant::now();
        let frame = render(&settings, &[scene.draw(&sampler)]).expect("render");
        println!("{name}: {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
        save(&frame, &out.join(format!("{name}.png")));
    }
    let sampler = lab_sampler(4);
    let t = Instant::now();
    let frame = render_reference(&base, &[scene.draw(&sampler)], spp, 1, None).expect("reference");
    println!("reference {spp}x{spp}: {:.2} s", t.elapsed().as_secs_f64());
    save(&frame, &out.join(format!("reference_{spp}.png")));
}
