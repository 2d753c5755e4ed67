//! The image is bit for bit the same for any thread count.

mod common;

use common::{lab_sampler, Ground};
use texel_raster::{render, render_reference, Derivatives, RenderSettings, View};

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

/// The colour view samples a row span at a time (`sample_batch`) unless texels are counted, which
/// takes the per-pixel path: both give the same image, bit for bit, for every lab filter, with and
/// without captured footprints.
#[test]
fn batched_and_per_pixel_sampling_give_identical_frames() {
    let (w, h) = (300, 170);
    let scene = Ground::new(w, h);
    // Without captured footprints, nearest and bilinear (lab modes 1 and 2) also skip derivatives.
    for (mode, capture_footprints) in (1..=8).flat_map(|m| [(m, true), (m, false)]) {
        let sampler = lab_sampler(mode);
        let settings = |count_texels| RenderSettings {
            count_texels,
            threads: Some(2),
            capture_footprints,
            ..RenderSettings::new(w, h)
        };
        let batched = render(&settings(false), &[scene.draw(&sampler)]).unwrap();
        let single = render(&settings(true), &[scene.draw(&sampler)]).unwrap();
        assert!(batched.covered_pixels() > 0);
        let bits = |f: &texel_raster::Frame| {
            f.color
                .iter()
                .flat_map(|c| c.map(f32::to_bits))
                .collect::<Vec<_>>()
        };
        assert_eq!(
            bits(&batched),
            bits(&single),
            "lab mode {mode} {capture_footprints}"
        );
        assert_eq!(batched.depth, single.depth);
        assert_eq!(batched.coverage, single.coverage);
        assert_eq!(batched.footprints, single.footprints);
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
