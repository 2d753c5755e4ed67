//! Clipping and robustness: near-plane crossing, behind the eye, huge coordinates, degenerate input.

mod common;

use common::{lab_sampler, white, Ground, Rng};
use glam::{Mat4, Vec2, Vec3};
use texel_raster::{camera, render, DrawCall, RasterError, RenderSettings, Vertex};

fn draw<'a>(
    vertices: &'a [Vertex],
    triangles: &'a [[u32; 3]],
    m: Mat4,
    tex: &'a (texel_texture::Texture, texel_texture::Sampler),
) -> DrawCall<'a> {
    DrawCall {
        vertices,
        triangles,
        texture: &tex.0,
        sampler: &tex.1,
        clip_from_world: m,
        material: None,
        uv_mapping: None,
    }
}

fn v(x: f32, y: f32, z: f32) -> Vertex {
    Vertex::new(Vec3::new(x, y, z), Vec2::ZERO)
}

#[test]
fn ground_crossing_the_near_plane_renders_the_visible_part_only() {
    // The ground's near edge is behind the eye. Every pixel whose ray meets the ground inside the
    // quad (beyond the near plane) is covered, and no pixel above the horizon is: away from the
    // horizon and the far corners (2 px band), coverage equals the analytic answer.
    let (w, h) = (256, 144);
    let scene = Ground::new(w, h);
    let sampler = lab_sampler(1);
    let frame = render(&RenderSettings::new(w, h), &[scene.draw(&sampler)]).unwrap();
    let horizon = {
        // The first row whose centre ray meets the ground.
        (0..h)
            .find(|&j| scene.analytic_uv(128.5, f64::from(j) + 0.5, w, h).is_some())
            .unwrap()
    };
    for j in 0..h {
        for i in 0..w {
            let covered = frame.covered(frame.index(i, j));
            if j + 2 < horizon {
                assert!(!covered, "sky pixel ({i}, {j}) covered");
            } else if j > horizon + 2 {
                assert!(covered, "ground pixel ({i}, {j}) not covered");
            }
        }
    }
    // The part behind the eye does not wrap around into the image: covered rows are contiguous.
    let rows: Vec<bool> = (0..h).map(|j| frame.covered(frame.index(128, j))).collect();
    let first = rows.iter().position(|&c| c).unwrap();
    assert!(rows[first..].iter().all(|&c| c));
}

#[test]
fn triangle_crossing_the_near_plane_matches_analytic_coverage() {
    // A triangle on the floor y = -1 with one vertex behind the eye; camera at the origin, looking
    // down -z. A pixel is covered iff its ray meets the floor inside the triangle, beyond the near
    // plane. Checked away from the edges (the ray hits at least 1e-2 inside every edge).
    let (w, h) = (128, 96);
    let tex = white();
    let near = 0.1;
    let m = camera::perspective(1.2, w as f32 / h as f32, near, 100.0);
    let p = [
        Vec3::new(-3.0, -1.0, -8.0),
        Vec3::new(4.0, -1.0, -6.0),
        Vec3::new(0.5, -1.0, 5.0),
    ];
    let vertices: Vec<Vertex> = p.iter().map(|q| v(q.x, q.y, q.z)).collect();
    let frame = render(
        &RenderSettings::new(w, h),
        &[draw(&vertices, &[[0, 1, 2]], m, &tex)],
    )
    .unwrap();
    let inv = m.as_dmat4().inverse();
    let (mut inside, mut outside) = (0, 0);
    for j in 0..h {
        for i in 0..w {
            let xn = 2.0 * (f64::from(i) + 0.5) / f64::from(w) - 1.0;
            let yn = 1.0 - 2.0 * (f64::from(j) + 0.5) / f64::from(h);
            let far = inv * glam::DVec4::new(xn, yn, 1.0, 1.0);
            let dir = far.truncate() / far.w;
            let covered = frame.covered(frame.index(i, j));
            if dir.y >= 0.0 {
                assert!(!covered, "({i}, {j}) above the horizon");
                continue;
            }
            let hit = dir * (-1.0 / dir.y);
            // Signed distances to the triangle's edges in the floor plane (xz), positive inside.
            let q: Vec<glam::DVec2> = p
                .iter()
                .map(|v| glam::DVec2::new(f64::from(v.x), f64::from(v.z)))
                .collect();
            let x = glam::DVec2::new(hit.x, hit.z);
            let orient = (q[1] - q[0]).perp_dot(q[2] - q[0]).signum();
            let d = (0..3)
                .map(|k| {
                    let (a, b) = (q[k], q[(k + 1) % 3]);
                    orient * (b - a).perp_dot(x - a) / (b - a).length()
                })
                .fold(f64::INFINITY, f64::min);
            let beyond_near = -hit.z > f64::from(near) + 1e-3;
            if d > 1e-2 && beyond_near {
                assert!(covered, "({i}, {j}) should be covered");
                inside += 1;
            } else if d < -1e-2 || -hit.z < f64::from(near) - 1e-3 {
                assert!(!covered, "({i}, {j}) should not be covered");
                outside += 1;
            }
        }
    }
    assert!(inside > 1000 && outside > 1000, "{inside} {outside}");
}

#[test]
fn triangle_behind_the_eye_renders_nothing() {
    let tex = white();
    let m = camera::perspective(1.0, 1.0, 0.1, 100.0);
    let vertices = [v(-1.0, -1.0, 2.0), v(1.0, -1.0, 2.0), v(0.0, 1.0, 3.0)];
    let both = [[0, 1, 2], [0, 2, 1]];
    let frame = render(
        &RenderSettings::new(32, 32),
        &[draw(&vertices, &both, m, &tex)],
    )
    .unwrap();
    assert_eq!(frame.covered_pixels(), 0);
}

#[test]
fn huge_coordinates_do_not_overflow() {
    let tex = white();
    let (w, h) = (64, 48);
    for big in [1e7f32, -1e7, 1e20, 1e38, f32::MAX] {
        // Orthographic (w = 1): a triangle covering the frame with one vertex far away.
        let vertices = [v(-1.5, -1.5, 0.0), v(big, -1.5, 0.0), v(-1.5, 1e7, 0.0)];
        let frame = render(
            &RenderSettings::new(w, h),
            &[draw(&vertices, &[[0, 1, 2]], Mat4::IDENTITY, &tex)],
        )
        .unwrap();
        if big > 0.0 {
            assert_eq!(frame.covered_pixels(), (w * h) as usize, "x = {big}");
        } else {
            assert_eq!(frame.covered_pixels(), 0, "x = {big}");
        }
        // Perspective: the same vertices in front of the camera.
        let m = camera::perspective(1.0, 4.0 / 3.0, 0.1, 1e9)
            * camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y);
        let frame = render(
            &RenderSettings::new(w, h),
            &[draw(&vertices, &[[0, 1, 2]], m, &tex)],
        )
        .unwrap();
        assert!(frame.color.iter().all(|c| c.iter().all(|x| x.is_finite())));
    }
    // Random huge triangles: no panic, finite output.
    let mut rng = Rng::new(9);
    let mut r = || ((rng.next_f64() - 0.5) * 2e7) as f32;
    let vertices: Vec<Vertex> = (0..300).map(|_| v(r(), r(), r() * 1e-7)).collect();
    let triangles: Vec<[u32; 3]> = (0..100).map(|k| [3 * k, 3 * k + 1, 3 * k + 2]).collect();
    let frame = render(
        &RenderSettings::new(w, h),
        &[draw(&vertices, &triangles, Mat4::IDENTITY, &tex)],
    )
    .unwrap();
    assert!(frame.color.iter().all(|c| c.iter().all(|x| x.is_finite())));
}

#[test]
fn degenerate_triangles_are_skipped() {
    let tex = white();
    let m = Mat4::IDENTITY;
    let cases: [[Vertex; 3]; 5] = [
        [v(-1.0, -1.0, 0.0), v(0.0, 0.0, 0.0), v(1.0, 1.0, 0.0)], // collinear
        [v(0.3, 0.3, 0.0), v(0.3, 0.3, 0.0), v(0.3, 0.3, 0.0)],   // a point
        [v(f32::NAN, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)],
        [
            v(f32::INFINITY, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            v(0.0, 1.0, 0.0),
        ],
        [v(-1.0, -1.0, 0.0), v(1.0, -1.0, 0.0), v(0.0, 1.0, f32::NAN)],
    ];
    for (k, c) in cases.iter().enumerate() {
        let frame = render(
            &RenderSettings::new(16, 16),
            &[draw(c, &[[0, 1, 2]], m, &tex)],
        )
        .unwrap();
        assert_eq!(frame.covered_pixels(), 0, "case {k}");
    }
    // A NaN matrix.
    let good = [v(-1.0, -1.0, 0.0), v(1.0, -1.0, 0.0), v(0.0, 1.0, 0.0)];
    let frame = render(
        &RenderSettings::new(16, 16),
        &[draw(&good, &[[0, 1, 2]], Mat4::NAN, &tex)],
    )
    .unwrap();
    assert_eq!(frame.covered_pixels(), 0);
}

#[test]
fn bad_input_is_a_typed_error() {
    let tex = white();
    let good = [v(-1.0, -1.0, 0.0), v(1.0, -1.0, 0.0), v(0.0, 1.0, 0.0)];
    let err = render(
        &RenderSettings::new(16, 16),
        &[draw(&good, &[[0, 1, 2], [0, 3, 1]], Mat4::IDENTITY, &tex)],
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            RasterError::IndexOutOfRange {
                draw: 0,
                triangle: 1,
                index: 3,
                vertex_count: 3
            }
        ),
        "{err}"
    );
    let d = [draw(&good, &[[0, 1, 2]], Mat4::IDENTITY, &tex)];
    for (w, h) in [(0, 10), (10, 0), (20000, 10)] {
        assert!(matches!(
            render(&RenderSettings::new(w, h), &d),
            Err(RasterError::InvalidSize { .. })
        ));
    }
    assert!(matches!(
        render(&RenderSettings::new(16384, 16384), &d),
        Err(RasterError::TooManyPixels { .. })
    ));
    let s = RenderSettings {
        threads: Some(0),
        ..RenderSettings::new(8, 8)
    };
    assert!(matches!(
        render(&s, &d),
        Err(RasterError::InvalidThreadCount(0))
    ));
    let s = RenderSettings {
        background: [f32::NAN, 0.0, 0.0, 1.0],
        ..RenderSettings::new(8, 8)
    };
    assert!(matches!(
        render(&s, &d),
        Err(RasterError::NonFiniteBackground(_))
    ));
    let s = RenderSettings::new(8, 8);
    assert!(matches!(
        texel_raster::render_reference(&s, &d, 0, 1, None),
        Err(RasterError::InvalidSamplesPerPixel { spp_side: 0, .. })
    ));
}

#[test]
fn backface_culling_and_depth() {
    let tex = white();
    let ccw = [v(-1.0, -1.0, 0.0), v(1.0, -1.0, 0.0), v(0.0, 1.0, 0.0)];
    let s = RenderSettings {
        cull_backfaces: true,
        ..RenderSettings::new(16, 16)
    };
    let front = render(&s, &[draw(&ccw, &[[0, 1, 2]], Mat4::IDENTITY, &tex)]).unwrap();
    let back = render(&s, &[draw(&ccw, &[[0, 2, 1]], Mat4::IDENTITY, &tex)]).unwrap();
    assert!(front.covered_pixels() > 50);
    assert_eq!(back.covered_pixels(), 0);
    // Depth: a red triangle in front of a white one wins whatever the draw order.
    let red = texel_texture::Texture::from_fn(
        1,
        1,
        texel_texture::Format::Rgba32Float,
        &Default::default(),
        |_, _| [1.0, 0.0, 0.0, 1.0],
    )
    .unwrap();
    let near_tri = [v(-1.0, -1.0, -0.5), v(1.0, -1.0, -0.5), v(0.0, 1.0, -0.5)];
    let far_tri = [v(-1.0, -1.0, 0.5), v(1.0, -1.0, 0.5), v(0.0, 1.0, 0.5)];
    let red_draw = DrawCall {
        texture: &red,
        ..draw(&near_tri, &[[0, 1, 2]], Mat4::IDENTITY, &tex)
    };
    let white_draw = draw(&far_tri, &[[0, 1, 2]], Mat4::IDENTITY, &tex);
    for order in [[red_draw, white_draw], [white_draw, red_draw]] {
        let f = render(&RenderSettings::new(16, 16), &order).unwrap();
        assert_eq!(f.color[f.index(8, 8)], [1.0, 0.0, 0.0, 1.0]);
        assert!((f.depth[f.index(8, 8)] + 0.5).abs() < 1e-6);
    }
}

/// Regression (fuzz target `raster`): clipping coordinates near 1e33 in `f64` rounded a vertex far
/// outside the guard band, its fixed-point position saturated at `i64::MAX` and the edge functions
/// overflowed. Every set-up edge must stay within the bound `setup.rs` documents.
#[test]
fn extreme_coordinates_keep_fixed_point_edges_bounded() {
    let positions = [
        [3853934000000000.0f32, -2.7368e-11, -1.1266637e-23],
        [-28172647000000.0, -1.874289e23, 6.7916946e24],
        [-6.9382367e-9, 6.7871653e24, -6.9382367e-9],
        [-74267896.0, 1.1728593e35, 393572150000000.0],
    ];
    let vertices: Vec<Vertex> = positions
        .iter()
        .map(|&p| Vertex::new(Vec3::from(p), Vec2::ZERO))
        .collect();
    let clip_from_world = Mat4::perspective_rh_gl(
        26301677000000.0f32.to_radians(),
        100.0 / 96.0,
        33.845303,
        -4.570989e-19,
    ) * Mat4::look_at_rh(
        Vec3::new(15628.749, 3.6691683e-22, 4.4329315e-38),
        Vec3::new(-1.5712015e-28, 2015374100000000.0, -169191700000000.0),
        Vec3::Y,
    );
    let tex = white();
    let triangles = [[0u32, 1, 2], [1, 0, 3]];
    let call = draw(&vertices, &triangles, clip_from_world, &tex);
    let settings = RenderSettings::new(100, 96);
    let mut out = Vec::new();
    for (t, tri) in triangles.iter().enumerate() {
        texel_raster::setup::setup_triangle(&settings, &call, 0, t as u32, *tri, &mut out);
    }
    for s in &out {
        for e in &s.edges {
            assert!(e.a.abs() < 1 << 27 && e.b.abs() < 1 << 27, "{e:?}");
        }
    }
    render(&settings, &[call]).unwrap();
}
