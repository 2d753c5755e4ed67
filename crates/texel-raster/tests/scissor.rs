//! The scissor rectangle: inside it every pixel is bit for bit the whole frame's, outside it the
//! frame keeps what it had (the background after a clear).

mod common;

use common::{lab_sampler, Ground};
use texel_raster::{
    draw_into, render, render_reference, Derivatives, Frame, RasterError, RenderSettings, View,
};

fn bits(c: [f32; 4]) -> [u32; 4] {
    c.map(f32::to_bits)
}

/// Check `part` against `whole` for the scissor `[x0, y0, x1, y1]`.
fn check(whole: &Frame, part: &Frame, [x0, y0, x1, y1]: [u32; 4], background: [f32; 4]) {
    let mut inside_covered = 0;
    for j in 0..whole.height {
        for i in 0..whole.width {
            let k = whole.index(i, j);
            if (x0..x1).contains(&i) && (y0..y1).contains(&j) {
                assert_eq!(
                    bits(part.color[k]),
                    bits(whole.color[k]),
                    "pixel ({i}, {j})"
                );
                assert_eq!(part.covered(k), whole.covered(k), "pixel ({i}, {j})");
                inside_covered += usize::from(whole.covered(k));
            } else {
                assert_eq!(part.color[k], background, "pixel ({i}, {j}) outside");
                assert!(!part.covered(k), "pixel ({i}, {j}) outside");
            }
        }
    }
    assert!(inside_covered > 100, "the scissor covers too little ground");
}

#[test]
fn scissored_pixels_equal_the_whole_frame_for_every_view_and_derivative() {
    let (w, h) = (300, 170); // not multiples of the tile size
    let scene = Ground::new(w, h);
    // Odd edges cut 2x2 quads and 64-pixel tiles.
    let scissor = [37, 61, 211, 143];
    for mode in [1, 4, 8] {
        let sampler = lab_sampler(mode);
        for view in [View::Color, View::Mip, View::Fetches] {
            for derivatives in [Derivatives::Analytic, Derivatives::Quad] {
                let settings = RenderSettings {
                    view,
                    derivatives,
                    ..RenderSettings::new(w, h)
                };
                let whole = render(&settings, &[scene.draw(&sampler)]).unwrap();
                let part = render(
                    &RenderSettings {
                        scissor: Some(scissor),
                        ..settings
                    },
                    &[scene.draw(&sampler)],
                )
                .unwrap();
                check(&whole, &part, scissor, settings.background);
            }
        }
    }
}

#[test]
fn two_scissored_draws_make_a_split_screen() {
    // Left of column 150 trilinear, right of it aniso16, drawn into one cleared frame: each side
    // equals its own whole frame.
    let (w, h) = (300, 170);
    let scene = Ground::new(w, h);
    let (left, right) = (lab_sampler(4), lab_sampler(8));
    let settings = RenderSettings::new(w, h);
    let mut frame = Frame::new(&settings);
    for (sampler, rect) in [(&left, [0, 0, 150, h]), (&right, [150, 0, w, h])] {
        let s = RenderSettings {
            scissor: Some(rect),
            ..settings
        };
        draw_into(&s, &[scene.draw(sampler)], &mut frame).unwrap();
    }
    let whole_left = render(&settings, &[scene.draw(&left)]).unwrap();
    let whole_right = render(&settings, &[scene.draw(&right)]).unwrap();
    let mut differ = 0;
    for j in 0..h {
        for i in 0..w {
            let k = frame.index(i, j);
            let want = if i < 150 { &whole_left } else { &whole_right };
            assert_eq!(
                bits(frame.color[k]),
                bits(want.color[k]),
                "pixel ({i}, {j})"
            );
            differ += usize::from(whole_left.color[k] != whole_right.color[k]);
        }
    }
    assert!(
        differ > 1000,
        "the two filters should differ near the horizon"
    );
}

#[test]
fn scissored_reference_equals_the_whole_reference_inside() {
    let (w, h) = (150, 90);
    let scene = Ground::new(w, h);
    let sampler = lab_sampler(4);
    let settings = RenderSettings::new(w, h);
    let scissor = [13, 40, 101, 77];
    let whole = render_reference(&settings, &[scene.draw(&sampler)], 2, 7, None).unwrap();
    let part = render_reference(
        &RenderSettings {
            scissor: Some(scissor),
            ..settings
        },
        &[scene.draw(&sampler)],
        2,
        7,
        None,
    )
    .unwrap();
    check(&whole, &part, scissor, settings.background);
}

#[test]
fn a_scissor_outside_the_frame_is_refused() {
    let scene = Ground::new(64, 32);
    let sampler = lab_sampler(1);
    for bad in [[0, 0, 65, 32], [10, 0, 5, 32], [0, 0, 64, 33]] {
        let settings = RenderSettings {
            scissor: Some(bad),
            ..RenderSettings::new(64, 32)
        };
        let err = render(&settings, &[scene.draw(&sampler)]).unwrap_err();
        assert!(matches!(err, RasterError::InvalidScissor { .. }), "{err}");
    }
    // An empty rectangle draws nothing.
    let settings = RenderSettings {
        scissor: Some([5, 5, 5, 20]),
        ..RenderSettings::new(64, 32)
    };
    let frame = render(&settings, &[scene.draw(&sampler)]).unwrap();
    assert_eq!(frame.covered_pixels(), 0);
}
