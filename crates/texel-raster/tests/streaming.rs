//! Streamed frames ([`texel_raster::Streaming`]): a draw into a frame that holds its clear may
//! draw each tile in scratch filled with the clear and stream it out with non-temporal stores.
//! The image must be bit for bit the frame drawn in place, for every colour target, view, thread
//! count, scissor, draw path and tile size at the frame's edges; a frame written by hand after
//! its clear must be drawn in place once told ([`Frame::forget_clear`]).
//!
//! The policy is process-wide, so these tests live in their own test binary and take turns
//! ([`POLICY`]).

mod common;

use common::{lab_sampler, Ground};
use texel_raster::{
    draw_into, last_level_cache_bytes, render, set_streaming, streaming, ColorTarget, Derivatives,
    Frame, Precision, RenderSettings, Streaming, View,
};

/// Held by each test while it sets the process-wide policy and draws.
static POLICY: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Colour and depth as bit patterns (`-0.0` and `0.0` differ, NaNs compare).
fn bits(f: &Frame) -> (Vec<u32>, Vec<[u8; 4]>, Vec<u32>) {
    let b = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    (b(f.color.as_flattened()), f.color8.clone(), b(&f.depth))
}

/// Reset `frame` and draw `scene` into it under `policy`; whether the draw streamed.
fn reset_and_draw(
    policy: Streaming,
    settings: &RenderSettings,
    scene: &Ground,
    mode: u8,
    frame: &mut Frame,
) -> bool {
    set_streaming(policy);
    assert_eq!(streaming(), policy);
    frame.reset(settings);
    assert!(frame.holds_clear());
    let streams = frame.draw_streams();
    let sampler = lab_sampler(mode);
    draw_into(settings, &[scene.draw(&sampler)], frame).unwrap();
    assert!(!frame.holds_clear(), "a draw forgets the clear");
    streams
}

#[test]
fn streamed_frames_equal_frames_drawn_in_place() {
    let _turn = POLICY.lock().unwrap_or_else(|e| e.into_inner());
    let cases = [
        // Partial tiles on the right and at the bottom; one tile row; exactly two tiles.
        (
            300,
            170,
            ColorTarget::Srgb8,
            View::Color,
            Derivatives::Analytic,
            4,
        ),
        (
            301,
            65,
            ColorTarget::Unorm8,
            View::Color,
            Derivatives::Analytic,
            2,
        ),
        (
            128,
            64,
            ColorTarget::Float,
            View::Color,
            Derivatives::Analytic,
            1,
        ),
        (
            300,
            170,
            ColorTarget::Srgb8,
            View::Color,
            Derivatives::Quad,
            3,
        ),
        (
            300,
            170,
            ColorTarget::Unorm8,
            View::Lod,
            Derivatives::Analytic,
            4,
        ),
        (300, 170, ColorTarget::Float, View::Uv, Derivatives::Quad, 4),
        (
            97,
            203,
            ColorTarget::Srgb8,
            View::Barycentric,
            Derivatives::Analytic,
            4,
        ),
    ];
    let mut compared = 0;
    for (w, h, target, view, derivatives, mode) in cases {
        let scene = Ground::new(w, h);
        for threads in [1, 2] {
            for scissor in [None, Some([13, 40, 250.min(w), 150.min(h)])] {
                for precision in [Precision::Exact, Precision::Gpu] {
                    let settings = RenderSettings {
                        target,
                        view,
                        derivatives,
                        precision,
                        scissor,
                        threads: Some(threads),
                        background: [0.25, 0.5, 0.75, 1.0],
                        ..RenderSettings::new(w, h)
                    };
                    let label = format!(
                        "{w}x{h} {target:?} {view:?} {derivatives:?} mode {mode}, \
                         {threads} threads, scissor {scissor:?}, {precision:?}"
                    );
                    let mut in_place = Frame::new(&settings);
                    let mut streamed = Frame::new(&settings);
                    assert!(!reset_and_draw(
                        Streaming::Never,
                        &settings,
                        &scene,
                        mode,
                        &mut in_place
                    ));
                    assert!(reset_and_draw(
                        Streaming::Always,
                        &settings,
                        &scene,
                        mode,
                        &mut streamed
                    ));
                    assert!(in_place.covered_pixels() > 0, "{label}");
                    assert!(bits(&in_place) == bits(&streamed), "{label}");
                    // A second draw on top loads the frame (it no longer holds the clear).
                    let sampler = lab_sampler(mode);
                    assert!(!streamed.draw_streams());
                    draw_into(&settings, &[scene.draw(&sampler)], &mut streamed).unwrap();
                    assert!(bits(&in_place) == bits(&streamed), "{label}, drawn twice");
                    compared += 1;
                }
            }
        }
    }
    assert_eq!(compared, 7 * 2 * 2 * 2);

    // Side channels are drawn in place whatever the policy.
    set_streaming(Streaming::Always);
    for settings in [
        RenderSettings {
            count_texels: true,
            ..RenderSettings::new(64, 64)
        },
        RenderSettings {
            capture_footprints: true,
            ..RenderSettings::new(64, 64)
        },
        RenderSettings {
            view: View::Fetches,
            ..RenderSettings::new(64, 64)
        },
    ] {
        assert!(!Frame::new(&settings).draw_streams());
    }

    // `Auto` streams a frame larger than the last-level cache, not one that fits.
    set_streaming(Streaming::Auto);
    let small = RenderSettings::new(64, 64);
    assert!(!Frame::new(&small).draw_streams());
    let cache = last_level_cache_bytes();
    if cache <= 256 << 20 {
        // 8 bytes a pixel (RGBA8 and depth), 1024 pixels a row.
        let rows = (cache / 8 / 1024 + 1) as u32;
        let eight = |rows| RenderSettings {
            target: ColorTarget::Srgb8,
            ..RenderSettings::new(1024, rows)
        };
        let large = eight(rows);
        assert!(Frame::new(&large).draw_streams(), "{rows} rows");
        let fits = eight(rows - 1);
        assert!(!Frame::new(&fits).draw_streams(), "{} rows", rows - 1);
    }
    set_streaming(Streaming::Auto);
}

/// The clear is remembered until a draw or `forget_clear`; it is not part of the frame's value.
/// A pixel written by hand after the clear survives a draw once the frame forgets its clear,
/// and is redrawn from the clear when it does not: the streamed path really skips the frame.
#[test]
fn hand_written_pixels_need_forget_clear() {
    let _turn = POLICY.lock().unwrap_or_else(|e| e.into_inner());
    set_streaming(Streaming::Always);
    let (w, h) = (200, 120);
    let settings = RenderSettings {
        target: ColorTarget::Srgb8,
        threads: Some(2),
        ..RenderSettings::new(w, h)
    };
    let scene = Ground::new(w, h);
    let sampler = lab_sampler(2);
    let fresh = render(&settings, &[scene.draw(&sampler)]).unwrap();
    assert!(!fresh.holds_clear());
    // A covered pixel near the bottom, and one the ground does not reach (the sky).
    let ground = fresh.index(100, 110);
    let sky = fresh.index(100, 2);
    assert!(fresh.covered(ground) && !fresh.covered(sky));

    let mut frame = Frame::new(&settings);
    assert!(frame.holds_clear());
    let cleared = frame.clone();
    assert!(cleared.holds_clear());
    frame.forget_clear();
    assert!(!frame.holds_clear());
    assert_eq!(frame, cleared, "the mark is not part of the frame's value");

    let mark = [255, 0, 255, 255];
    for forget in [false, true] {
        frame.reset(&settings);
        for k in [ground, sky] {
            frame.color8[k] = mark;
            frame.depth[k] = -1.0;
        }
        if forget {
            frame.forget_clear();
        }
        assert_eq!(frame.draw_streams(), !forget);
        draw_into(&settings, &[scene.draw(&sampler)], &mut frame).unwrap();
        if forget {
            // Loaded: the hand-written pixels are nearer than the ground and stay.
            assert_eq!(frame.color8[ground], mark);
            assert_eq!(frame.color8[sky], mark);
        } else {
            // Drawn from the clear: the ground's tile is the fresh image.
            assert_eq!(frame.color8[ground], fresh.color8[ground]);
            assert_eq!(frame.depth[ground], fresh.depth[ground]);
        }
    }
    set_streaming(Streaming::Auto);
}

/// `render` and `render_into` (which reset and draw) give the same bits streamed and in place, and
/// a draw whose settings name another background than the reset's keeps the reset's clear in the
/// pixels it does not cover, streamed as in place: the clear is what the frame holds.
#[test]
fn render_paths_and_the_resets_clear_stream_alike() {
    use texel_raster::render_into;
    let _turn = POLICY.lock().unwrap_or_else(|e| e.into_inner());
    let (w, h) = (260, 150);
    let scene = Ground::new(w, h);
    let sampler = lab_sampler(4);
    for target in [ColorTarget::Srgb8, ColorTarget::Float] {
        let settings = RenderSettings {
            target,
            threads: Some(2),
            background: [0.25, 0.5, 0.75, 1.0],
            ..RenderSettings::new(w, h)
        };
        let mut frames = Vec::new();
        for policy in [Streaming::Never, Streaming::Always] {
            set_streaming(policy);
            let fresh = render(&settings, &[scene.draw(&sampler)]).unwrap();
            let mut reused = Frame::new(&settings);
            render_into(&settings, &[scene.draw(&sampler)], &mut reused).unwrap();
            assert!(bits(&fresh) == bits(&reused), "{target:?} {policy:?}");
            // Reset with one background, draw with another.
            let other = RenderSettings {
                background: [1.0, 0.0, 0.0, 1.0],
                ..settings
            };
            let mut mixed = Frame::new(&settings);
            assert_eq!(mixed.draw_streams(), policy == Streaming::Always);
            draw_into(&other, &[scene.draw(&sampler)], &mut mixed).unwrap();
            frames.push((fresh, mixed));
        }
        let ((fresh, mixed), (fresh_s, mixed_s)) = (&frames[0], &frames[1]);
        assert!(bits(fresh) == bits(fresh_s), "render, {target:?}");
        assert!(bits(mixed) == bits(mixed_s), "reset A, draw B, {target:?}");
        // The uncovered pixels hold the reset's background.
        let sky = mixed.index(w / 2, 1);
        assert!(!mixed.covered(sky));
        assert_eq!(mixed.linear()[sky], fresh.linear()[sky]);
    }
    set_streaming(Streaming::Auto);
}
