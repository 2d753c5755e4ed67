//! The image is bit for bit the same for any thread count.

mod common;

use common::{lab_sampler, screen_grid, Ground};
use glam::{Mat4, Vec3};
use texel_raster::{render, render_reference, Derivatives, DrawCall, RenderSettings, View};

#[test]
fn one_and_two_threads_give_identical_frames() {
    let (w, h) = (300, 170); // not multiples of the tile size
    let scene = Ground::new(w, h);
    let sampler = lab_sampler(4);
    for view in [
        View::Color,
        View::Uv,
        View::Mip,
        View::Lod,
        View::Aniso,
        View::Fetches,
        View::Barycentric,
    ] {
        for derivatives in [Derivatives::Analytic, Derivatives::Quad] {
            let settings = |threads| RenderSettings {
                view,
                derivatives,
                threads: Some(threads),
                capture_footprints: true,
                ..RenderSettings::new(w, h)
            };
            let one = render(&settings(1), &[scene.draw(&sampler)]).unwrap();
            let two = render(&settings(2), &[scene.draw(&sampler)]).unwrap();
            let three = render(&settings(3), &[scene.draw(&sampler)]).unwrap();
            assert!(one.covered_pixels() > 0);
            // Compare bits (PartialEq on f32 would accept -0 == 0).
            let bits = |f: &texel_raster::Frame| {
                f.color
                    .iter()
                    .flat_map(|c| c.map(f32::to_bits))
                    .collect::<Vec<_>>()
            };
            assert_eq!(bits(&one), bits(&two), "{view:?} {derivatives:?}");
            assert_eq!(bits(&one), bits(&three), "{view:?} {derivatives:?}");
            assert_eq!(one, two);
        }
    }
}

/// Render `draw` with batched sampling (the colour view) and with the per-pixel path (texel
/// counting) and require the same frame, bit for bit, with and without captured footprints.
fn assert_batched_equals_per_pixel(w: u32, h: u32, draw: DrawCall, label: &str) {
    for capture_footprints in [true, false] {
        let settings = |count_texels| RenderSettings {
            count_texels,
            threads: Some(2),
            capture_footprints,
            ..RenderSettings::new(w, h)
        };
        let batched = render(&settings(false), &[draw]).unwrap();
        let single = render(&settings(true), &[draw]).unwrap();
        assert!(batched.covered_pixels() > 0, "{label}");
        let bits = |f: &texel_raster::Frame| {
            f.color
                .iter()
                .flat_map(|c| c.map(f32::to_bits))
                .collect::<Vec<_>>()
        };
        assert_eq!(
            bits(&batched),
            bits(&single),
            "{label} {capture_footprints}"
        );
        assert_eq!(batched.depth, single.depth, "{label}");
        assert_eq!(batched.footprints, single.footprints, "{label}");
    }
}

/// The colour view samples a triangle's fragments in batches (`sample_batch`) unless texels are
/// counted, which takes the per-pixel path: both give the same image, bit for bit, for every lab
/// filter. Without captured footprints, nearest and bilinear (lab modes 1 and 2) also skip
/// derivatives.
#[test]
fn batched_and_per_pixel_sampling_give_identical_frames() {
    let (w, h) = (300, 170);
    let scene = Ground::new(w, h);
    for mode in 1..=8 {
        let sampler = lab_sampler(mode);
        let label = format!("ground, lab mode {mode}");
        assert_batched_equals_per_pixel(w, h, scene.draw(&sampler), &label);
    }
}

/// As above for meshes of small triangles, whose batches gather several rows (a triangle of a few
/// pixels per row): a 60 x 40 grid of 5 x 4-pixel cells seen head-on, and the same grid tilted in
/// perspective so that its triangles shrink to fractions of a pixel towards the far edge.
#[test]
fn batched_small_triangles_equal_per_pixel() {
    let (w, h) = (300, 170);
    let (vertices, triangles, texture) = screen_grid(w, h, 60, 40);
    let tilt = Mat4::perspective_rh_gl(1.0, w as f32 / h as f32, 0.1, 10.0)
        * Mat4::look_at_rh(Vec3::new(0.0, -1.6, 0.6), Vec3::new(0.0, 0.4, 0.0), Vec3::Z);
    for (name, clip_from_world) in [("head-on", Mat4::IDENTITY), ("tilted", tilt)] {
        for mode in 1..=8 {
            let sampler = lab_sampler(mode);
            let draw = DrawCall {
                vertices: &vertices,
                triangles: &triangles,
                texture: &texture,
                sampler: &sampler,
                clip_from_world,
                material: None,
                uv_mapping: None,
            };
            let label = format!("{name} grid, lab mode {mode}");
            assert_batched_equals_per_pixel(w, h, draw, &label);
        }
    }
}

#[test]
fn reference_is_identical_for_any_thread_count_and_deterministic() {
    let (w, h) = (140, 80);
    let scene = Ground::new(w, h);
    let sampler = lab_sampler(4);
    let run = |threads, seed| {
        let s = RenderSettings {
            threads: Some(threads),
            ..RenderSettings::new(w, h)
        };
        render_reference(&s, &[scene.draw(&sampler)], 4, seed, None).unwrap()
    };
    let a = run(1, 7);
    assert_eq!(a, run(2, 7));
    assert_eq!(a, run(1, 7));
    assert_ne!(a, run(2, 8), "a different seed jitters differently");
}

/// `render_into` reuses a frame and gives `render`'s frame bit for bit, across size and side-channel
/// changes; `draw_into` refuses a frame not reset for its settings and draws on top of one that is.
#[test]
fn reused_frames_equal_fresh_ones() {
    use texel_raster::{draw_into, render_into, Frame, RasterError};
    let sampler = lab_sampler(4);
    let mut frame = Frame::new(&RenderSettings::new(8, 8));
    for (w, h, capture, view) in [
        (300, 170, false, View::Color),
        (300, 170, true, View::Fetches),
        (64, 65, false, View::Color),
        (300, 170, false, View::Color),
    ] {
        let scene = Ground::new(w, h);
        let settings = RenderSettings {
            view,
            capture_footprints: capture,
            threads: Some(2),
            ..RenderSettings::new(w, h)
        };
        let fresh = render(&settings, &[scene.draw(&sampler)]).unwrap();
        render_into(&settings, &[scene.draw(&sampler)], &mut frame).unwrap();
        assert!(frame.matches(&settings));
        assert!(fresh.covered_pixels() > 0);
        assert_eq!(frame, fresh, "{w}x{h} {view:?}");
        // A second draw of the same triangles on top changes nothing: equal depths keep the first.
        draw_into(&settings, &[scene.draw(&sampler)], &mut frame).unwrap();
        assert_eq!(frame, fresh, "{w}x{h} {view:?} drawn twice");
        // Reset then draw is render_into.
        frame.reset(&settings);
        assert_eq!(frame.covered_pixels(), 0);
        draw_into(&settings, &[scene.draw(&sampler)], &mut frame).unwrap();
        assert_eq!(frame, fresh);
    }
    // A frame of another size, or without the side channel the settings write, is refused untouched.
    let scene = Ground::new(300, 170);
    let before = frame.clone();
    let counting = RenderSettings {
        count_texels: true,
        ..RenderSettings::new(300, 170)
    };
    for settings in [RenderSettings::new(299, 170), counting] {
        let err = draw_into(&settings, &[scene.draw(&sampler)], &mut frame).unwrap_err();
        assert!(matches!(err, RasterError::FrameMismatch { .. }), "{err}");
        assert_eq!(frame, before);
    }
}
