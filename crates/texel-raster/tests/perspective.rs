//! Perspective-correct interpolation: exact against ray/plane intersection; equal to affine at w = 1.

mod common;

use common::{lab_sampler, Ground};
use glam::{Mat4, Vec2, Vec3};
use proptest::prelude::*;
use texel_raster::setup::setup_draws;
use texel_raster::{DrawCall, Perspective, RenderSettings, Vertex};

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
