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
