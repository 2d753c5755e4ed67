//! The image is bit for bit the same for any thread count.

mod common;

use common::{lab_sampler, screen_grid, Ground};
use glam::{Mat4, Vec2, Vec3, Vec4};
use texel_raster::{
    render, render_reference, Derivatives, DrawCall, Light, Material, RenderSettings, TextureInput,
    UvEvaluation, UvMapping, View, MAX_LIGHTS,
};
use texel_texture::mapping::sphere::SurfaceProjection;

#[test]
fn one_and_two_threads_give_identical_frames() {
    let (w, h) = (300, 170); // not multiples of the tile size
    let scene = Ground::new(w, h);
    let sampler = lab_sampler(4);
    for view in View::ALL {
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
    assert_batched_equals_per_pixel_in(&RenderSettings::new(w, h), draw, label);
}

/// As [`assert_batched_equals_per_pixel`] under `base` settings (lights, say).
fn assert_batched_equals_per_pixel_in(base: &RenderSettings, draw: DrawCall, label: &str) {
    assert_draws_batched_equal_per_pixel(base, &[draw], label);
}

/// As [`assert_batched_equals_per_pixel`] for several draws in order.
fn assert_draws_batched_equal_per_pixel(base: &RenderSettings, draws: &[DrawCall], label: &str) {
    for capture_footprints in [true, false] {
        let settings = |count_texels| RenderSettings {
            count_texels,
            threads: Some(2),
            capture_footprints,
            ..*base
        };
        let batched = render(&settings(false), draws).unwrap();
        let single = render(&settings(true), draws).unwrap();
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

/// The span path's other branches against the per-pixel path: lit draws without a material,
/// lit draws with a normal-mapped material, vertex colours, and a per-pixel sphere mapping (the
/// span computes barycentrics only for these), for a filter that ignores derivatives (lab mode 2)
/// and one that reads them (mode 4).
#[test]
fn batched_shaded_and_mapped_draws_equal_per_pixel() {
    let (w, h) = (300, 170);
    let scene = Ground::new(w, h);
    let mut lights = [None; MAX_LIGHTS];
    lights[0] = Some(Light::Directional {
        direction: Vec3::new(-0.4, 1.0, 0.3),
        intensity: Vec3::splat(2.0),
    });
    let lit = RenderSettings {
        lights,
        ..RenderSettings::new(w, h)
    };
    let plain = RenderSettings::new(w, h);
    let mut coloured = scene.vertices.clone();
    for (k, v) in coloured.iter_mut().enumerate() {
        v.color = Vec4::new(0.2 + 0.2 * k as f32, 1.0 - 0.2 * k as f32, 0.5, 1.0);
    }
    for mode in [2, 4] {
        let sampler = lab_sampler(mode);
        let draw = scene.draw(&sampler);
        assert_batched_equals_per_pixel_in(&lit, draw, &format!("lit, mode {mode}"));
        let material = Material {
            roughness: 0.4,
            normal_map: Some(TextureInput {
                texture: &scene.texture,
                sampler: &sampler,
            }),
            ..Material::default()
        };
        let with_material = DrawCall {
            material: Some(material),
            ..draw
        };
        let label = format!("lit, normal map, mode {mode}");
        assert_batched_equals_per_pixel_in(&lit, with_material, &label);
        let label = format!("unlit, material, mode {mode}");
        assert_batched_equals_per_pixel_in(&plain, with_material, &label);
        let vertex_coloured = DrawCall {
            vertices: &coloured,
            ..draw
        };
        let label = format!("vertex colours, mode {mode}");
        assert_batched_equals_per_pixel_in(&plain, vertex_coloured, &label);
        let mapped = DrawCall {
            uv_mapping: Some(UvMapping {
                projection: SurfaceProjection::Equirect,
                centre: Vec3::new(0.0, -3.0, -20.0),
                evaluation: UvEvaluation::PerPixel,
            }),
            ..draw
        };
        let label = format!("sphere-mapped, mode {mode}");
        assert_batched_equals_per_pixel_in(&plain, mapped, &label);
    }
}

/// Two draws that cross in depth, so that the second one's rows pass the depth test only in
/// part (the span's compaction) and elsewhere in whole (its contiguous runs): a grid whose depth
/// rises from left to right, then a flat one in front of its right part, in big triangles (3 x 2
/// cells) and small ones (60 x 40).
#[test]
fn batched_equals_per_pixel_where_draws_cross_in_depth() {
    let (w, h) = (300, 170);
    for (nx, ny) in [(3, 2), (60, 40)] {
        let (mut sloped, triangles, texture) = screen_grid(w, h, nx, ny);
        let mut flat = sloped.clone();
        for v in &mut sloped {
            v.position.z = 0.5 * v.position.x + 0.05 * v.position.y;
        }
        for v in &mut flat {
            v.position.z = 0.1;
            v.uv = Vec2::new(v.uv.y, v.uv.x);
        }
        for mode in [1, 2, 4] {
            let sampler = lab_sampler(mode);
            let draw = |vertices| DrawCall {
                vertices,
                triangles: &triangles,
                texture: &texture,
                sampler: &sampler,
                clip_from_world: Mat4::IDENTITY,
                material: None,
                uv_mapping: None,
            };
            let base = RenderSettings::new(w, h);
            let label = format!("{nx} x {ny} cells, lab mode {mode}");
            let draws = [draw(&sloped), draw(&flat)];
            assert_draws_batched_equal_per_pixel(&base, &draws, &label);
            // Both draws really show: the flat one's constant depth on the right, the sloped
            // one's on the left.
            let frame = render(&base, &draws).unwrap();
            let depth = |i, j| frame.depth[frame.index(i, j)];
            assert_eq!(depth(280, 85), depth(250, 40), "{label}");
            assert_ne!(depth(20, 85), depth(280, 85), "{label}");
            assert_ne!(depth(20, 85), depth(40, 85), "{label}");
        }
    }
}

/// Draws with different samplers in the same tiles: the span scratch keeps its footprints
/// between draws, and an unshaded draw whose sampler ignores derivatives (nearest, bilinear)
/// writes only `u` and `v`, leaving the derivatives of an earlier draw (trilinear, mip-nearest)
/// in place. Those are never read: the frames equal the per-pixel path's, bit for bit, in either
/// order, with and without captured footprints (which write every field).
#[test]
fn batched_equals_per_pixel_when_samplers_alternate() {
    let (w, h) = (300, 170);
    let (mut sloped, triangles, texture) = screen_grid(w, h, 60, 40);
    let mut flat = sloped.clone();
    for v in &mut sloped {
        v.position.z = 0.5 * v.position.x + 0.05 * v.position.y;
    }
    for v in &mut flat {
        v.position.z = 0.1;
        v.uv = Vec2::new(v.uv.y * 3.0, v.uv.x * 2.0);
    }
    for (first, second) in [(4, 2), (2, 4), (3, 1), (1, 4)] {
        let (a, b) = (lab_sampler(first), lab_sampler(second));
        let draw = |vertices, sampler| DrawCall {
            vertices,
            triangles: &triangles,
            texture: &texture,
            sampler,
            clip_from_world: Mat4::IDENTITY,
            material: None,
            uv_mapping: None,
        };
        let draws = [draw(&sloped, &a), draw(&flat, &b), draw(&sloped, &b)];
        let label = format!("lab modes {first} then {second}");
        assert_draws_batched_equal_per_pixel(&RenderSettings::new(w, h), &draws, &label);
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
