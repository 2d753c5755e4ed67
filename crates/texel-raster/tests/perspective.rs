//! Perspective-correct interpolation: exact against ray/plane intersection; equal to affine at w = 1.

mod common;

use common::{lab_sampler, Ground};
use glam::{DVec2, Mat4, Vec2, Vec3};
use proptest::prelude::*;
use texel_raster::setup::setup_draws;
use texel_raster::{Derivatives, DrawCall, Perspective, RenderSettings, Vertex};

#[test]
fn ground_uv_matches_ray_plane_intersection() {
    let (w, h) = (320, 180);
    let scene = Ground::new(w, h);
    let sampler = lab_sampler(4);
    let settings = RenderSettings::new(w, h);
    let setups = setup_draws(&settings, &[scene.draw(&sampler)]).unwrap();
    let texels = f64::from(scene.texture.width());
    let (mut checked, mut worst) = (0, 0.0f64);
    for j in 0..h {
        for i in 0..w {
            let Some(t) = setups.iter().find(|t| t.covers(i, j)) else {
                continue;
            };
            let (x, y) = (f64::from(i) + 0.5, f64::from(j) + 0.5);
            let uvs = scene.draw(&sampler).vertices;
            let uvs = t.indices.map(|k| uvs[k as usize].uv.as_dvec2());
            let uv = t.barycentrics(x, y, Perspective::Correct).interpolate2(uvs);
            let exact = scene
                .analytic_uv(x, y, w, h)
                .expect("covered pixels see the ground");
            let err = ((uv - exact) * texels).abs().max_element();
            worst = worst.max(err);
            assert!(
                err < 1e-4,
                "pixel ({i}, {j}): uv {uv} vs exact {exact}: {err} texels"
            );
            checked += 1;
        }
    }
    // Everything below the horizon (about row 85.2 of 180) is covered.
    assert!(checked > 320 * 90, "{checked} pixels checked");
    assert!(worst < 1e-4);
}

/// The rasterizer's own `uv` (`f32` planes re-anchored per tile: the footprints it hands the
/// sampler, in the span, per-pixel and quad paths) against the exact ray-plane intersection,
/// modulo the period, on the ground with a 256-texel texture (u reaches 250 periods): within
/// 1e-4 texel where the image is magnified (a pixel spans less than a texel; 3.9e-7 of a period,
/// about 6.5 `f32` ulps of a `u` in `[0.5, 1)`) and elsewhere within 1e-4 of the footprint's
/// extent; in the analytic paths (span, per pixel) the four derivatives are within 1e-5 of the
/// largest of the `f64` barycentrics' derivatives.
/// Measured: 3.95e-5 texel (1.5e-7 period), 4.5e-5 of the extent, derivatives 7.9e-7. The `f64` barycentrics
/// above keep 1e-4 texel of a 1024-texel texture at any distance.
#[test]
fn rendered_footprints_match_the_ray_plane_intersection() {
    const BOUND: f64 = 1e-4;
    const REL: f64 = 1e-4;
    const DERIV: f64 = 1e-5;
    let (w, h) = (1280, 720);
    let scene = Ground::with_texture(w, h, common::checker(256, 8));
    let sampler = lab_sampler(4);
    let texels = f64::from(scene.texture.width());
    let base = RenderSettings {
        capture_footprints: true,
        ..RenderSettings::new(w, h)
    };
    let setups = setup_draws(&base, &[scene.draw(&sampler)]).unwrap();
    let vertices = scene.draw(&sampler).vertices;
    let paths = [
        ("span", base),
        (
            "per pixel",
            RenderSettings {
                count_texels: true,
                ..base
            },
        ),
        (
            "quads",
            RenderSettings {
                derivatives: Derivatives::Quad,
                ..base
            },
        ),
    ];
    for (name, settings) in paths {
        let frame = texel_raster::render(&settings, &[scene.draw(&sampler)]).unwrap();
        let (mut magnified, mut worst_mag, mut worst_rel) = (0, 0.0f64, 0.0f64);
        let mut worst_deriv = 0.0f64;
        for j in 0..h {
            for i in 0..w {
                let k = frame.index(i, j);
                if !frame.covered(k) {
                    continue;
                }
                let (x, y) = (f64::from(i) + 0.5, f64::from(j) + 0.5);
                let exact = scene.analytic_uv(x, y, w, h).unwrap();
                let fp = frame.footprints[k];
                let got = DVec2::new(f64::from(fp.u), f64::from(fp.v));
                // Distance modulo one period (repeat), in texels.
                let d = (got - exact) - (got - exact).round();
                let err = (d * texels).abs().max_element();
                let extent = [fp.dudx, fp.dudy, fp.dvdx, fp.dvdy]
                    .iter()
                    .fold(0.0f64, |m, d| m.max(f64::from(d.abs())))
                    * texels;
                // The analytic paths' four derivatives against the f64 barycentrics' (quads
                // difference neighbouring pixels instead: a different quantity).
                if name != "quads" {
                    let t = setups.iter().find(|t| t.covers(i, j)).unwrap();
                    let uvs = t.indices.map(|k| vertices[k as usize].uv.as_dvec2());
                    let (dx, dy) = t.barycentrics(x, y, Perspective::Correct).derivatives2(uvs);
                    let got = [fp.dudx, fp.dvdx, fp.dudy, fp.dvdy].map(f64::from);
                    let want = [dx.x, dx.y, dy.x, dy.y];
                    let scale = want.iter().fold(0.0f64, |m, d| m.max(d.abs()));
                    for (g, e) in got.iter().zip(want) {
                        let rel = (g - e).abs() / scale;
                        worst_deriv = worst_deriv.max(rel);
                        assert!(rel < DERIV, "{name} ({i}, {j}): derivative {g} vs {e}");
                    }
                }
                if extent < 1.0 {
                    magnified += 1;
                    worst_mag = worst_mag.max(err);
                    assert!(err < BOUND, "{name} ({i}, {j}): {err} texels");
                } else {
                    worst_rel = worst_rel.max(err / extent);
                    assert!(
                        err < REL * extent,
                        "{name} ({i}, {j}): {err}, extent {extent}"
                    );
                }
            }
        }
        eprintln!(
            "{name}: {magnified} magnified pixels, worst {worst_mag:.2e} texel; elsewhere \
             {worst_rel:.2e} of the extent; derivatives within {worst_deriv:.2e} of the largest"
        );
        assert!(magnified > 50_000, "{name}: {magnified}");
    }
}

#[test]
fn affine_differs_from_correct_under_perspective() {
    let (w, h) = (320, 180);
    let scene = Ground::new(w, h);
    let sampler = lab_sampler(4);
    let setups = setup_draws(&RenderSettings::new(w, h), &[scene.draw(&sampler)]).unwrap();
    let t = setups.iter().find(|t| t.covers(160, 170)).unwrap();
    let c = t.lambda_at(160.5, 170.5, Perspective::Correct);
    let a = t.lambda_at(160.5, 170.5, Perspective::Affine);
    assert!((c - a).abs().max_element() > 1e-3, "{c} {a}");
}

fn vertex(p: (f32, f32), uv: (f32, f32)) -> Vertex {
    Vertex::new(Vec3::new(p.0, p.1, 0.0), Vec2::new(uv.0, uv.1))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// With w = 1 everywhere (clip_from_world = I), perspective-correct equals affine.
    #[test]
    fn w_one_makes_correct_equal_affine(
        p in prop::array::uniform3((-1.5f32..1.5, -1.5f32..1.5)),
        uv in prop::array::uniform3((-4f32..4.0, -4f32..4.0)),
        pts in prop::collection::vec((0.0f64..64.0, 0.0f64..48.0), 16),
    ) {
        let (tex, sampler) = common::white();
        let vertices: Vec<Vertex> = (0..3).map(|k| vertex(p[k], uv[k])).collect();
        let draw = DrawCall {
            vertices: &vertices,
            triangles: &[[0, 1, 2]],
            texture: &tex,
            sampler: &sampler,
            clip_from_world: Mat4::IDENTITY,
            material: None,
            uv_mapping: None,
        };
        let setups = setup_draws(&RenderSettings::new(64, 48), &[draw]).unwrap();
        let uvs = [0, 1, 2].map(|k| vertices[k].uv.as_dvec2());
        for t in &setups {
            for &(x, y) in &pts {
                let c = t.barycentrics(x, y, Perspective::Correct);
                let a = t.barycentrics(x, y, Perspective::Affine);
                let (uc, ua) = (c.interpolate2(uvs), a.interpolate2(uvs));
                let scale = 1.0 + uc.abs().max_element();
                prop_assert!((uc - ua).abs().max_element() < 1e-9 * scale, "{} {}", uc, ua);
                let (dc, da) = (c.derivatives2(uvs), a.derivatives2(uvs));
                let d = (dc.0 - da.0).abs().max_element().max((dc.1 - da.1).abs().max_element());
                prop_assert!(d < 1e-9 * (1.0 + dc.0.abs().max_element() + dc.1.abs().max_element()));
            }
        }
    }
}
