//! Derivatives for the sampler: analytic vs finite differences; quad differences within 2x2 quads.

mod common;

use common::{Ground, Rng};
use glam::{DVec2, Vec2, Vec3};
use texel_raster::setup::{setup_draws, TriangleSetup};
use texel_raster::{camera, render, Derivatives, DrawCall, Perspective, RenderSettings, Vertex};
use texel_texture::{AddressMode, Filter, Sampler, SamplerDescriptor};

fn uv_at(t: &TriangleSetup, uvs: [DVec2; 3], x: f64, y: f64) -> DVec2 {
    t.barycentrics(x, y, Perspective::Correct).interpolate2(uvs)
}

/// Analytic derivatives at every covered pixel centre against central differences (h = 1e-3 px)
/// of the analytic uv, 1e-3 relative.
fn check_against_finite_differences(
    setups: &[TriangleSetup],
    vertices: &[Vertex],
    w: u32,
    h: u32,
) -> usize {
    let mut checked = 0;
    let hstep = 1e-3;
    for j in 0..h {
        for i in 0..w {
            let Some(t) = setups.iter().find(|t| t.covers(i, j)) else {
                continue;
            };
            let uvs = t.indices.map(|k| vertices[k as usize].uv.as_dvec2());
            let (x, y) = (f64::from(i) + 0.5, f64::from(j) + 0.5);
            let b = t.barycentrics(x, y, Perspective::Correct);
            let (dx, dy) = b.derivatives2(uvs);
            let fdx = (uv_at(t, uvs, x + hstep, y) - uv_at(t, uvs, x - hstep, y)) / (2.0 * hstep);
            let fdy = (uv_at(t, uvs, x, y + hstep) - uv_at(t, uvs, x, y - hstep)) / (2.0 * hstep);
            let scale = dx.abs().max_element().max(dy.abs().max_element());
            let err = (dx - fdx)
                .abs()
                .max_element()
                .max((dy - fdy).abs().max_element());
            assert!(
                err <= 1e-3 * scale,
                "pixel ({i}, {j}): analytic {dx} {dy}, finite {fdx} {fdy}"
            );
            checked += 1;
        }
    }
    checked
}

#[test]
fn analytic_derivatives_match_finite_differences_on_the_ground() {
    let (w, h) = (200, 120);
    let scene = Ground::new(w, h);
    let sampler = common::lab_sampler(4);
    let setups = setup_draws(&RenderSettings::new(w, h), &[scene.draw(&sampler)]).unwrap();
    let n = check_against_finite_differences(&setups, &scene.vertices, w, h);
    assert!(n > 200 * 60, "{n}");
}

#[test]
fn analytic_derivatives_match_finite_differences_on_random_triangles() {
    let (w, h) = (96, 64);
    let (tex, sampler) = common::white();
    let mut rng = Rng::new(42);
    let mut r = |a: f64, b: f64| (a + (b - a) * rng.next_f64()) as f32;
    let proj = camera::perspective(1.0, 1.5, 0.1, 100.0);
    let view = camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y);
    let mut checked = 0;
    for _ in 0..20 {
        let vertices: Vec<Vertex> = (0..3)
            .map(|_| {
                Vertex::new(
                    Vec3::new(r(-2.0, 2.0), r(-2.0, 2.0), r(-2.5, 2.5)),
                    Vec2::new(r(-3.0, 3.0), r(-3.0, 3.0)),
                )
            })
            .collect();
        let draw = DrawCall {
            vertices: &vertices,
            triangles: &[[0, 1, 2]],
            texture: &tex,
            sampler: &sampler,
            clip_from_world: proj * view,
            material: None,
            uv_mapping: None,
        };
        let setups = setup_draws(&RenderSettings::new(w, h), &[draw]).unwrap();
        checked += check_against_finite_differences(&setups, &vertices, w, h);
    }
    assert!(checked > 2000, "{checked}");
}

#[test]
fn quad_derivatives_are_differences_within_each_quad() {
    let (w, h) = (160, 90);
    let scene = Ground::new(w, h);
    // Clamp: no periodic reduction of uv, so footprint uvs are directly comparable.
    let sampler = Sampler::new(
        SamplerDescriptor::from(Filter::Trilinear).with_address_mode(AddressMode::ClampToEdge),
    )
    .unwrap();
    let settings = RenderSettings {
        derivatives: Derivatives::Quad,
        capture_footprints: true,
        ..RenderSettings::new(w, h)
    };
    let frame = render(&settings, &[scene.draw(&sampler)]).unwrap();
    let mut quads = 0;
    for qj in (0..h).step_by(2) {
        for qi in (0..w).step_by(2) {
            let px = [(qi, qj), (qi + 1, qj), (qi, qj + 1), (qi + 1, qj + 1)]
                .map(|(i, j)| frame.index(i, j));
            if !px.iter().all(|&k| frame.covered(k)) {
                continue;
            }
            let f = px.map(|k| frame.footprints[k]);
            let close = |d: f32, a: f32, b: f32| {
                let tol = 2.0 * f32::EPSILON * a.abs().max(b.abs()) + 1e-6 * d.abs();
                (d - (b - a)).abs() <= tol
            };
            for (k, (l, r)) in [(0, (0, 1)), (1, (0, 1)), (2, (2, 3)), (3, (2, 3))] {
                assert!(
                    close(f[k].dudx, f[l].u, f[r].u),
                    "quad ({qi}, {qj}) pixel {k}: {:?}",
                    f
                );
                assert!(
                    close(f[k].dvdx, f[l].v, f[r].v),
                    "quad ({qi}, {qj}) pixel {k}"
                );
            }
            for (k, (t, b)) in [(0, (0, 2)), (2, (0, 2)), (1, (1, 3)), (3, (1, 3))] {
                assert!(
                    close(f[k].dudy, f[t].u, f[b].u),
                    "quad ({qi}, {qj}) pixel {k}"
                );
                assert!(
                    close(f[k].dvdy, f[t].v, f[b].v),
                    "quad ({qi}, {qj}) pixel {k}"
                );
            }
            // Pixels in the same row share d/dx, in the same column d/dy.
            assert_eq!(f[0].dudx, f[1].dudx);
            assert_eq!(f[0].dvdy, f[2].dvdy);
            quads += 1;
        }
    }
    assert!(quads > 80 * 20, "{quads}");
}

#[test]
fn quad_and_analytic_derivatives_agree_where_uv_is_smooth() {
    // Near the bottom of the ground scene uv is nearly affine over a pixel: quad differences
    // (forward differences over one pixel) approximate the analytic derivative within 5%.
    let (w, h) = (160, 90);
    let scene = Ground::new(w, h);
    let sampler = common::lab_sampler(4);
    let run = |d| {
        let s = RenderSettings {
            derivatives: d,
            capture_footprints: true,
            ..RenderSettings::new(w, h)
        };
        render(&s, &[scene.draw(&sampler)]).unwrap()
    };
    let (a, q) = (run(Derivatives::Analytic), run(Derivatives::Quad));
    for j in 70..90 {
        for i in 0..w {
            let k = a.index(i, j);
            let (fa, fq) = (a.footprints[k], q.footprints[k]);
            assert!(
                (fa.dudx - fq.dudx).abs() <= 0.05 * fa.dudx.abs(),
                "({i}, {j}) {fa:?} {fq:?}"
            );
            assert!(
                (fa.dvdy - fq.dvdy).abs() <= 0.05 * fa.dvdy.abs(),
                "({i}, {j}) {fa:?} {fq:?}"
            );
        }
    }
}
