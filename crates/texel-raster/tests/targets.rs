//! Colour targets: an 8-bit target stores exactly the encoding of what the float target stores,
//! for every view, derivative mode and draw path, and `draw_into` on top of an 8-bit frame
//! depth-tests against the frame's depth as on a float frame. Every copy of the tile code the CPU
//! can run (the baseline, and the run-time dispatched x86-64-v3 and x86-64-v4 copies) draws the
//! same bits.

mod common;

use common::{lab_sampler, screen_grid, Ground};
use glam::Mat4;
use texel_raster::{
    draw_into, limit_level, render, simd_level, ColorTarget, Derivatives, DrawCall, Frame,
    RenderSettings, SimdLevel, Vertex, View,
};
use texel_texture::{Filter, Sampler, Texture};

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

/// Whether two frames hold the same bits: colour (float or 8-bit) and depth compared as bit
/// patterns, so `-0.0` and `0.0` differ and NaNs compare.
fn same_bits(a: &Frame, b: &Frame) -> bool {
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let color = |f: &Frame| bits(f.color.as_flattened());
    a.color8 == b.color8 && color(a) == color(b) && bits(&a.depth) == bits(&b.depth)
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
    // The copies this CPU runs, the best last.
    let best = simd_level();
    let levels: Vec<SimdLevel> = SimdLevel::ALL.into_iter().filter(|&l| l <= best).collect();
    for &l in SimdLevel::ALL.iter().filter(|&&l| l > best) {
        println!(
            "skipped: this CPU cannot run the {} copy of the tile code",
            l.name()
        );
    }
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
                    // Every lower copy of the tile code draws the same bits as the CPU's best,
                    // into the 8-bit and the float target (whose bits no encode can hide).
                    for &level in &levels[..levels.len() - 1] {
                        limit_level(level);
                        assert_eq!(simd_level(), level);
                        let lower = render(&s(target), &[draw]).unwrap();
                        let lower_float = render(&s(ColorTarget::Float), &[draw]).unwrap();
                        limit_level(best);
                        assert!(
                            same_bits(&lower, &eight),
                            "{label}: {level:?} against {best:?}"
                        );
                        assert!(
                            same_bits(&lower_float, &float),
                            "{label}, float: {level:?} against {best:?}"
                        );
                    }
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

/// Nearest samplers write unshaded texels into an 8-bit target of the texture's own format as
/// stored bytes (`SpanKind::Stored`): the frame must still be the float frame's
/// encoding, texel for texel and at the border, and the other pairings (the other format, vertex
/// colours) must take the shading path to the same result.
#[test]
fn copied_texels_are_the_encoded_float_frame() {
    use texel_texture::{
        AddressMode, BorderColor, Format, Limits, MipmapFilterMode, SamplerDescriptor,
    };
    let (w, h) = (300, 170);
    let noise = |format| {
        Texture::from_fn(61, 47, format, &Limits::default(), |i, j| {
            let k = (i * 7919 + j * 104_729) % 997;
            [
                (k % 97) as f32 / 96.0,
                (k % 13) as f32 / 12.0,
                (k % 251) as f32 / 250.0,
                (k % 5) as f32 / 4.0,
            ]
        })
        .unwrap()
    };
    let textures = [noise(Format::Rgba8Srgb), noise(Format::Rgba8Unorm)];
    let samplers: Vec<Sampler> = [
        (
            MipmapFilterMode::None,
            AddressMode::Repeat,
            BorderColor::OpaqueWhite,
        ),
        (
            MipmapFilterMode::Nearest,
            AddressMode::MirrorRepeat,
            BorderColor::OpaqueWhite,
        ),
        (
            MipmapFilterMode::Nearest,
            AddressMode::ClampToBorder,
            BorderColor::Custom([0.3, 0.6, 0.9, 0.5]),
        ),
    ]
    .into_iter()
    .map(|(mipmap_filter, addr, border_color)| {
        let d = SamplerDescriptor {
            mipmap_filter,
            border_color,
            ..SamplerDescriptor::from(Filter::Nearest).with_address_mode(addr)
        };
        Sampler::new(d).unwrap()
    })
    .collect();
    let (verts, tris, _) = screen_grid(w, h, 23, 11);
    // The grid's uv reaches past [0, 1] so that the border and the wrapping are read.
    let wide: Vec<Vertex> = verts
        .iter()
        .map(|v| Vertex::new(v.position, v.uv * 3.0 - 1.0))
        .collect();
    let mut tinted = wide.clone();
    tinted[5].color = glam::Vec4::new(0.5, 1.0, 1.0, 1.0);
    for tex in &textures {
        let ground = Ground::with_texture(w, h, noise(tex.format()));
        for s in &samplers {
            let wants = texel_texture::Wants {
                stored_bytes: true,
                fixed8: false,
            };
            assert_eq!(s.bind(tex, wants).kind(), texel_texture::SpanKind::Stored);
            for target in [ColorTarget::Srgb8, ColorTarget::Unorm8] {
                let draws = [
                    ("ground", ground.draw(s)),
                    ("grid", screen_draw(&wide, &tris, tex, s)),
                    ("tinted grid", screen_draw(&tinted, &tris, tex, s)),
                ];
                for (name, draw) in draws {
                    let label =
                        format!("{:?} {:?} {target:?} {name}", tex.format(), s.descriptor());
                    let float = render(&settings(w, h, ColorTarget::Float), &[draw]).unwrap();
                    let eight = render(&settings(w, h, target), &[draw]).unwrap();
                    assert_encoded(&float, &eight, target, &label);
                }
            }
        }
    }
}

/// `Precision::Gpu` on a unorm8 texture: the unshaded draw written as the fixed-point codes
/// (into a unorm8 target) equals the same codes decoded, shaded and encoded (into a float
/// target), the per-pixel path (texel counting, quad derivatives) gives the batched path's
/// colours, and every pixel lies within 3 codes of the exact frame (the bound
/// `texel_texture::fixed8` states for a mip blend).
#[test]
fn gpu_precision_is_the_same_on_every_path_and_near_exact() {
    use texel_raster::Precision;
    use texel_texture::{Format, Limits};
    let (w, h) = (300, 170);
    let noise = Texture::from_fn(64, 64, Format::Rgba8Unorm, &Limits::default(), |i, j| {
        let k = (i * 7919 + j * 104_729) % 997;
        [
            (k % 97) as f32 / 96.0,
            (k % 13) as f32 / 12.0,
            (k % 251) as f32 / 250.0,
            1.0,
        ]
    })
    .unwrap();
    let ground = Ground::with_texture(w, h, noise);
    for mode in [2, 3, 4] {
        let sampler = lab_sampler(mode);
        let draw = ground.draw(&sampler);
        let gpu = |target, derivatives, count_texels| RenderSettings {
            precision: Precision::Gpu,
            derivatives,
            count_texels,
            ..settings(w, h, target)
        };
        let label = format!("mode {mode}");
        let float = render(
            &gpu(ColorTarget::Float, Derivatives::Analytic, false),
            &[draw],
        )
        .unwrap();
        let eight = render(
            &gpu(ColorTarget::Unorm8, Derivatives::Analytic, false),
            &[draw],
        )
        .unwrap();
        assert_encoded(&float, &eight, ColorTarget::Unorm8, &label);
        let counted = render(
            &gpu(ColorTarget::Unorm8, Derivatives::Analytic, true),
            &[draw],
        )
        .unwrap();
        assert!(
            counted.color8 == eight.color8,
            "{label}: counting changed the colours"
        );
        let exact = render(&settings(w, h, ColorTarget::Unorm8), &[draw]).unwrap();
        let (mut max, mut differ) = (0, 0);
        for (a, b) in exact.color8.iter().zip(&eight.color8) {
            let d = (0..4).map(|c| a[c].abs_diff(b[c])).max().unwrap();
            max = max.max(d);
            differ += usize::from(d > 0);
        }
        assert!(max <= 3, "{label}: {max} codes from exact");
        // The fixed-point path did run: a textured ground differs somewhere.
        assert!(differ > 0, "{label}: identical to exact");
        // Quad derivatives go through the per-pixel path with the same kernels.
        let quad_gpu =
            render(&gpu(ColorTarget::Unorm8, Derivatives::Quad, false), &[draw]).unwrap();
        let quad_float =
            render(&gpu(ColorTarget::Float, Derivatives::Quad, false), &[draw]).unwrap();
        assert_encoded(&quad_float, &quad_gpu, ColorTarget::Unorm8, &label);
    }
}
