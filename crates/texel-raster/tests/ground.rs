//! The ground scene renders correctly: checks receding to the horizon with every filter, debug
//! views, shading.

mod common;

use common::{lab_sampler, white, Ground};
use glam::{Mat4, Vec2, Vec3, Vec4};
use texel_raster::views::MIP_PALETTE;
use texel_raster::{
    render, render_reference, DrawCall, Frame, Light, RenderSettings, Vertex, View,
};

const W: u32 = 320;
const H: u32 = 180;

fn horizon(scene: &Ground) -> u32 {
    (0..H)
        .find(|&j| scene.analytic_uv(160.5, f64::from(j) + 0.5, W, H).is_some())
        .unwrap()
}

#[test]
fn nearest_shows_the_exact_check_at_every_pixel_centre() {
    let scene = Ground::new(W, H);
    let sampler = lab_sampler(1);
    let frame = render(&RenderSettings::new(W, H), &[scene.draw(&sampler)]).unwrap();
    let mut checked = 0;
    for j in horizon(&scene) + 3..H {
        for i in 0..W {
            let uv = scene
                .analytic_uv(f64::from(i) + 0.5, f64::from(j) + 0.5, W, H)
                .unwrap();
            let xy = uv * 1024.0;
            let cell = (xy / 128.0).floor();
            let frac = xy / 128.0 - cell;
            // Skip centres within 1e-3 check of a check boundary.
            if frac.min_element() < 1e-3 || frac.max_element() > 1.0 - 1e-3 {
                continue;
            }
            let white = (cell.x + cell.y).rem_euclid(2.0) == 1.0;
            let expect = if white {
                [1.0; 4]
            } else {
                [0.0, 0.0, 0.0, 1.0]
            };
            assert_eq!(
                frame.color[frame.index(i, j)],
                expect,
                "pixel ({i}, {j}) uv {uv}"
            );
            checked += 1;
        }
    }
    assert!(checked > 20_000, "{checked}");
}

fn band_mad(a: &Frame, b: &Frame, rows: std::ops::Range<u32>) -> f64 {
    let mut s = 0.0;
    let mut n = 0;
    for j in rows {
        for i in 0..W {
            let k = a.index(i, j);
            s += f64::from((a.color[k][0] - b.color[k][0]).abs());
            n += 1;
        }
    }
    s / f64::from(n)
}

#[test]
fn every_filter_renders_and_mipmapping_beats_aliasing_near_the_horizon() {
    let scene = Ground::new(W, H);
    let s = RenderSettings::new(W, H);
    let reference = render_reference(&s, &[scene.draw(&lab_sampler(2))], 8, 11, None).unwrap();
    let band = horizon(&scene) + 2..horizon(&scene) + 30;
    let mut errors = Vec::new();
    for mode in 1..=4 {
        let sampler = lab_sampler(mode);
        let frame = render(&s, &[scene.draw(&sampler)]).unwrap();
        assert!(frame
            .color
            .iter()
            .all(|c| c.iter().all(|x| (0.0..=1.0).contains(x))));
        assert_eq!(frame.coverage(), {
            let r = render(&s, &[scene.draw(&lab_sampler(1))]).unwrap();
            r.coverage()
        });
        errors.push(band_mad(&frame, &reference, band.clone()));
    }
    // Nearest and bilinear (no mipmaps) alias badly in the minified band; mipmapping is far closer
    // to the supersampled reference.
    let [nearest, bilinear, mip_nearest, trilinear] = [errors[0], errors[1], errors[2], errors[3]];
    assert!(trilinear < 0.5 * nearest, "{errors:?}");
    assert!(trilinear < 0.5 * bilinear, "{errors:?}");
    assert!(mip_nearest < 0.5 * nearest, "{errors:?}");
}

fn srgb8(frame: &Frame, i: u32, j: u32) -> [u8; 4] {
    let k = 4 * frame.index(i, j);
    frame.to_srgb8()[k..k + 4].try_into().unwrap()
}

#[test]
fn uv_view_shows_fract_uv() {
    let scene = Ground::new(W, H);
    let sampler = lab_sampler(4);
    let s = RenderSettings {
        view: View::Uv,
        ..RenderSettings::new(W, H)
    };
    let frame = render(&s, &[scene.draw(&sampler)]).unwrap();
    let bytes = frame.to_srgb8();
    for j in (horizon(&scene) + 3..H).step_by(7) {
        for i in (0..W).step_by(5) {
            let uv = scene
                .analytic_uv(f64::from(i) + 0.5, f64::from(j) + 0.5, W, H)
                .unwrap();
            let fr = uv - uv.floor();
            if fr.min_element() < 0.01 || fr.max_element() > 0.99 {
                continue;
            }
            let k = 4 * frame.index(i, j);
            let (r, g) = (f64::from(bytes[k]), f64::from(bytes[k + 1]));
            assert!(
                (r - fr.x * 255.0).abs() <= 1.0 && (g - fr.y * 255.0).abs() <= 1.0,
                "({i}, {j}) {uv} {r} {g}"
            );
            assert_eq!(bytes[k + 2], 0);
        }
    }
}

#[test]
fn mip_view_levels_grow_towards_the_horizon() {
    let scene = Ground::new(W, H);
    let sampler = lab_sampler(4);
    let s = RenderSettings {
        view: View::Mip,
        ..RenderSettings::new(W, H)
    };
    let frame = render(&s, &[scene.draw(&sampler)]).unwrap();
    let level = |j| {
        let c = srgb8(&frame, 160, j);
        MIP_PALETTE
            .iter()
            .position(|p| p[..] == c[..3])
            .expect("a palette colour")
    };
    let levels: Vec<usize> = (horizon(&scene) + 1..H).map(level).collect();
    assert!(levels.windows(2).all(|w| w[0] >= w[1]), "{levels:?}");
    assert!(levels[0] >= 8 && *levels.last().unwrap() <= 4, "{levels:?}");
}

#[test]
fn fetch_counts_per_filter() {
    let scene = Ground::new(W, H);
    let count = |mode, view| {
        let s = RenderSettings {
            view,
            count_texels: true,
            ..RenderSettings::new(W, H)
        };
        render(&s, &[scene.draw(&lab_sampler(mode))]).unwrap()
    };
    let nearest = count(1, View::Color);
    let bilinear = count(2, View::Fetches);
    let trilinear = count(4, View::Aniso);
    for k in 0..nearest.depth.len() {
        if nearest.covered(k) {
            assert_eq!(nearest.texels_read[k], 1);
            assert_eq!(bilinear.texels_read[k], 4);
            assert!((4..=8).contains(&trilinear.texels_read[k]));
        } else {
            assert_eq!(nearest.texels_read[k], 0);
        }
    }
    assert!(trilinear.texels_read.contains(&8));
    // Counting off leaves the buffer empty.
    assert!(
        render(&RenderSettings::new(W, H), &[scene.draw(&lab_sampler(1))])
            .unwrap()
            .texels_read
            .is_empty()
    );
}

#[test]
fn vertex_colours_barycentrics_and_lambert() {
    let (w, h) = (60, 60);
    let (tex, sampler) = white();
    let mut vertices = vec![
        Vertex::new(Vec3::new(-1.0, -1.0, 0.0), Vec2::ZERO),
        Vertex::new(Vec3::new(1.0, -1.0, 0.0), Vec2::ZERO),
        Vertex::new(Vec3::new(-1.0, 1.0, 0.0), Vec2::ZERO),
    ];
    vertices[0].color = Vec4::new(1.0, 0.0, 0.0, 1.0);
    vertices[1].color = Vec4::new(0.0, 1.0, 0.0, 1.0);
    vertices[2].color = Vec4::new(0.0, 0.0, 1.0, 1.0);
    let draw = DrawCall {
        vertices: &vertices,
        triangles: &[[0, 1, 2]],
        texture: &tex,
        sampler: &sampler,
        clip_from_world: Mat4::IDENTITY,
        material: None,
        uv_mapping: None,
    };
    let color = render(&RenderSettings::new(w, h), &[draw]).unwrap();
    let bary = render(
        &RenderSettings {
            view: View::Barycentric,
            ..RenderSettings::new(w, h)
        },
        &[draw],
    )
    .unwrap();
    // Pixel (10, 40) has its centre at NDC (-0.65, -0.35): lambda = (0.5, 0.175, 0.325).
    let c = color.color[color.index(10, 40)];
    let expect = [0.5, 0.175, 0.325];
    for k in 0..3 {
        assert!((c[k] - expect[k]).abs() < 1e-6, "{c:?}");
    }
    let b = srgb8(&bary, 10, 40);
    for k in 0..3 {
        assert!((f32::from(b[k]) - expect[k] * 255.0).abs() <= 1.0, "{b:?}");
    }
    // Lambert (no material): normal +z, light at 60 degrees from +z with illuminance 0.8 pi:
    // 0.8 pi / pi * cos 60 + ambient 0.1 = 0.5.
    let mut lights = [None; texel_raster::MAX_LIGHTS];
    lights[0] = Some(Light::Directional {
        direction: Vec3::new(0.0, 3f32.sqrt(), 1.0),
        intensity: Vec3::splat(0.8 * std::f32::consts::PI),
    });
    lights[3] = Some(Light::Ambient {
        intensity: Vec3::splat(0.1),
    });
    let lit = RenderSettings {
        lights,
        ..RenderSettings::new(w, h)
    };
    let mut lit_vertices = vertices.clone();
    for v in &mut lit_vertices {
        v.color = Vec4::ONE;
        v.normal = Vec3::Z * 2.0;
    }
    let draw = DrawCall {
        vertices: &lit_vertices,
        ..draw
    };
    let f = render(&lit, &[draw]).unwrap();
    let c = f.color[f.index(10, 40)];
    assert!(
        (c[0] - 0.5).abs() < 1e-6 && (c[3] - 1.0).abs() < 1e-6,
        "{c:?}"
    );
}
