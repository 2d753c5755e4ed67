//! Colour targets: an 8-bit target stores exactly the encoding of what the float target stores,
//! for every view, derivative mode and draw path, and `draw_into` on top of an 8-bit frame
//! depth-tests against the frame's depth as on a float frame. The tile code's baseline copy and
//! its run-time dispatched x86-64-v3 copy draw the same bits.

mod common;

use common::{lab_sampler, screen_grid, Ground};
use glam::Mat4;
use texel_raster::{
    draw_into, force_baseline, render, simd_level, ColorTarget, Derivatives, DrawCall, Frame,
    RenderSettings, Vertex, View,
};
use texel_texture::{Sampler, Texture};

fn settings(w: u32, h: u32, target: ColorTarget) -> RenderSettings<'static> {
    RenderSettings {
        target,
        threads: Some(2),
        background: [0.25, 0.5, 0.75, 1.0],
        ..RenderSettings::new(w, h)
    }
}

/// The float frame's bytes in `target`'s encoding must be the 8-bit frame's, and the depths equal.
fn assert_encoded(float: &Frame, eight: &Frame, target: ColorTarget, label: &str) {
    assert!(float.color8.is_empty() && eight.color.is_empty(), "{label}");
    assert_eq!(eight.target, target);
    let want: Vec<[u8; 4]> = float.color.iter().map(|&c| target.encode(c)).collect();
    let differing = want
        .iter()
        .zip(&eight.color8)
        .filter(|(a, b)| a != b)
        .count();
    assert!(differing == 0, "{label}: {differing} pixels differ");
    assert_eq!(float.depth, eight.depth, "{label}");
    assert!(eight.covered_pixels() > 0, "{label}");
}

/// A draw of screen-space vertices (`common::screen_grid`'s).
fn screen_draw<'a>(
    vertices: &'a [Vertex],
    triangles: &'a [[u32; 3]],
    texture: &'a Texture,
    sampler: &'a Sampler,
) -> DrawCall<'a> {
    DrawCall {
        vertices,
        triangles,
        texture,
        sampler,
        clip_from_world: Mat4::IDENTITY,
        material: None,
        uv_mapping: None,
    }
}

#[test]
fn eight_bit_targets_store_the_float_targets_encoding() {
    let (w, h) = (300, 170); // not multiples of the tile size
    let ground = Ground::new(w, h);
    let sampler = lab_sampler(4);
    let (verts, tris, tex) = screen_grid(w, h, 23, 11);
    let grid_sampler = lab_sampler(2);
    let grid = screen_draw(&verts, &tris, &tex, &grid_sampler);
    for target in [ColorTarget::Srgb8, ColorTarget::Unorm8] {
        for view in [View::Color, View::Uv, View::Mip, View::Fetches] {
            for derivatives in [Derivatives::Analytic, Derivatives::Quad] {
                for (name, draw) in [("ground", ground.draw(&sampler)), ("grid", grid)] {
                    let label = format!("{target:?} {view:?} {derivatives:?} {name}");
                    let s = |t| RenderSettings {
                        view,
                        derivatives,
                        ..settings(w, h, t)
                    };
                    let float = render(&s(ColorTarget::Float), &[draw]).unwrap();
                    let eight = render(&s(target), &[draw]).unwrap();
                    assert_encoded(&float, &eight, target, &label);
                    // The baseline copy of the tile code draws the same bits as the CPU's best.
                    force_baseline(true);
                    let baseline = render(&s(target), &[draw]).unwrap();
                    force_baseline(false);
                    assert!(baseline == eight, "{label}: {:?}", simd_level());
                }
            }
        }
    }
}

#[test]
fn drawing_on_top_of_an_eight_bit_frame_keeps_the_nearer_fragments() {
    let (w, h) = (200, 120);
    let ground = Ground::new(w, h);
    let sampler = lab_sampler(4);
    let (verts, tris, tex) = screen_grid(w, h, 7, 5);
    let grid_sampler = lab_sampler(1);
    let grid = screen_draw(&verts, &tris, &tex, &grid_sampler);
    for target in [ColorTarget::Float, ColorTarget::Srgb8] {
        let s = settings(w, h, target);
        let mut frame = render(&s, &[ground.draw(&sampler)]).unwrap();
        let ground_only = frame.clone();
        draw_into(&s, &[grid], &mut frame).unwrap();
        assert_ne!(
            frame.depth, ground_only.depth,
            "the grid is drawn in front somewhere"
        );
        let together = render(&s, &[ground.draw(&sampler), grid]).unwrap();
        assert_eq!(frame, together, "{target:?}");
    }
    // A frame cleared for one target is refused by a draw into another.
    let mut frame = Frame::new(&settings(w, h, ColorTarget::Srgb8));
    assert!(draw_into(&settings(w, h, ColorTarget::Float), &[grid], &mut frame).is_err());
}
