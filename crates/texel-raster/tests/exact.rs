//! The exact reference against closed forms and an independent quadrature: covered areas, linear
//! ramps, one magnified texel, Repeat over hundreds of periods, a perspective checkerboard, the
//! seam between a quad's triangles, and the pixels that fall back to sampling.

mod common;

use common::{checker, screen_vertex, Ground};
use glam::{DVec2, Mat4, Vec4};
use texel_raster::{
    render_exact, render_reference_adaptive, DrawCall, ExactImage, ReferencePlan, RenderSettings,
    Vertex,
};
use texel_texture::{AddressMode, Format, Limits, Sampler, SamplerDescriptor, Texture};

fn sampler(mode: AddressMode) -> Sampler {
    Sampler::new(SamplerDescriptor::default().with_address_mode(mode)).unwrap()
}

fn float_texture(w: u32, h: u32, f: impl Fn(u32, u32) -> [f32; 4]) -> Texture {
    Texture::from_fn(w, h, Format::Rgba32Float, &Limits::default(), f).unwrap()
}

/// A screen-space quad over `[x0, x1] x [y0, y1]` pixels of a `w x h` frame with the given uvs at
/// its corners (top-left, top-right, bottom-right, bottom-left), as two triangles sharing the
/// diagonal from top-left to bottom-right.
fn quad(w: u32, h: u32, rect: [f64; 4], uvs: [[f32; 2]; 4]) -> Vec<Vertex> {
    let [x0, y0, x1, y1] = rect;
    [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
        .iter()
        .zip(uvs)
        .map(|(&(x, y), uv)| Vertex {
            uv: uv.into(),
            ..screen_vertex(x, y, w, h)
        })
        .collect()
}

const QUAD: [[u32; 3]; 2] = [[0, 2, 1], [0, 3, 2]];

fn draw<'a>(
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

fn at(e: &ExactImage, w: u32, i: u32, j: u32) -> [f32; 4] {
    e.color[(j * w + i) as usize]
}

#[test]
fn a_constant_texture_gives_its_value_times_the_covered_area() {
    // The right triangle (0, 0), (8, 0), (0, 8): pixel (i, j) is covered wholly when
    // i + j <= 6, by half when i + j = 7 (the hypotenuse is its diagonal), and not at all beyond.
    let (w, h) = (8, 8);
    let grey = [0.25f32, 0.5, 0.75, 1.0];
    let texture = float_texture(4, 4, |_, _| grey);
    let s = sampler(AddressMode::Repeat);
    let vertices = vec![
        screen_vertex(0.0, 0.0, w, h),
        screen_vertex(8.0, 0.0, w, h),
        screen_vertex(0.0, 8.0, w, h),
    ];
    let tris = [[0, 2, 1]];
    let mut settings = RenderSettings::new(w, h);
    settings.background = [1.0, 0.0, 0.0, 0.5];
    let e = render_exact(&settings, &[draw(&vertices, &tris, &texture, &s)], None).unwrap();
    assert!(e.exact.iter().all(|&x| x));
    for j in 0..h {
        for i in 0..w {
            let area = match i + j {
                0..=6 => 1.0,
                7 => 0.5,
                _ => 0.0,
            };
            let c = at(&e, w, i, j);
            for k in 0..4 {
                let expected = grey[k] * area + settings.background[k] * (1.0 - area);
                assert!(
                    (c[k] - expected).abs() < 1e-6,
                    "({i}, {j}) channel {k}: {} vs {expected}",
                    c[k]
                );
            }
        }
    }
}

#[test]
fn a_linear_ramp_under_an_affine_map_is_its_value_at_the_pixel_centre() {
    // 32 x 32 texels over 16 x 16 pixels: pixel i spans s in [2i - 1/2, 2i + 3/2]. The bilinear
    // reconstruction of a ramp is the ramp wherever it is not clamped, and the box filter of a
    // linear function is its value at the centre, 2i + 1/2. Pixel 0 reaches the clamped half
    // texel: its mean is (1/2) integral_0^(3/2) s / 31 ds = 9 / (16 * 31).
    let (w, h) = (16, 16);
    let texture = float_texture(32, 32, |i, j| [i as f32 / 31.0, j as f32 / 31.0, 0.5, 1.0]);
    let s = sampler(AddressMode::ClampToEdge);
    let vertices = quad(
        w,
        h,
        [0.0, 0.0, 16.0, 16.0],
        [[0., 0.], [1., 0.], [1., 1.], [0., 1.]],
    );
    let settings = RenderSettings::new(w, h);
    let e = render_exact(&settings, &[draw(&vertices, &QUAD, &texture, &s)], None).unwrap();
    assert!(e.exact.iter().all(|&x| x));
    let expected = |i: u32| {
        if i == 0 {
            9.0 / (16.0 * 31.0)
        } else if i == 15 {
            // Symmetric at the far edge: 1 - 9 / (16 * 31).
            1.0 - 9.0 / (16.0 * 31.0)
        } else {
            (2.0 * f64::from(i) + 0.5) / 31.0
        }
    };
    for j in 0..h {
        for i in 0..w {
            let c = at(&e, w, i, j);
            assert!(
                (f64::from(c[0]) - expected(i)).abs() < 1e-6,
                "({i}, {j}) r {}",
                c[0]
            );
            assert!(
                (f64::from(c[1]) - expected(j)).abs() < 1e-6,
                "({i}, {j}) g {}",
                c[1]
            );
            assert!((c[2] - 0.5).abs() < 1e-6);
        }
    }
    // The diagonal pixels (i = j) are split between the quad's two triangles: no seam.
    for i in 1..15 {
        let c = at(&e, w, i, i);
        assert!((f64::from(c[0]) - expected(i)).abs() < 1e-6, "diagonal {i}");
    }
}

#[test]
fn a_single_magnified_texel_cell_gives_the_bilinear_value_at_the_centre() {
    // A 2 x 2 texture over 64 x 64 pixels: pixels 16 ..= 47 lie inside the one bilinear cell
    // between the four texel centres, where the box filter of a bilinear function is its value
    // at the centre.
    let (w, h) = (64, 64);
    let t = [[0.1f32, 0.9], [0.7, 0.3]];
    let texture = float_texture(2, 2, |i, j| {
        let v = t[j as usize][i as usize];
        [v, 1.0 - v, v * v, 1.0]
    });
    let s = sampler(AddressMode::ClampToEdge);
    let vertices = quad(
        w,
        h,
        [0.0, 0.0, 64.0, 64.0],
        [[0., 0.], [1., 0.], [1., 1.], [0., 1.]],
    );
    let settings = RenderSettings::new(w, h);
    let e = render_exact(&settings, &[draw(&vertices, &QUAD, &texture, &s)], None).unwrap();
    for j in 16..48 {
        for i in 16..48 {
            let a = (f64::from(i) + 0.5) / 32.0 - 0.5;
            let b = (f64::from(j) + 0.5) / 32.0 - 0.5;
            let lerp = |f: &dyn Fn(f32) -> f32| {
                let v = |x: usize, y: usize| f64::from(f(t[y][x]));
                (1.0 - b) * ((1.0 - a) * v(0, 0) + a * v(1, 0))
                    + b * ((1.0 - a) * v(0, 1) + a * v(1, 1))
            };
            let c = at(&e, w, i, j);
            assert!((f64::from(c[0]) - lerp(&|v| v)).abs() < 1e-6, "({i}, {j})");
            assert!((f64::from(c[1]) - lerp(&|v| 1.0 - v)).abs() < 1e-6);
            assert!((f64::from(c[2]) - lerp(&|v| v * v)).abs() < 1e-6);
        }
    }
}

/// `integral_a^b` of the piecewise-linear interpolation of the periodic knots `k` (knot `n` at
/// `x = n`), summed cell by cell (the trapezoid rule is exact on each cell).
fn periodic_integral(k: &[f64], a: f64, b: f64) -> f64 {
    let n = k.len() as i64;
    let g = |x: f64| {
        let i = x.floor();
        let f = x - i;
        let i = i as i64;
        (1.0 - f) * k[i.rem_euclid(n) as usize] + f * k[(i + 1).rem_euclid(n) as usize]
    };
    let mut sum = 0.0;
    let mut x = a;
    while x < b {
        let next = (x.floor() + 1.0).min(b);
        sum += 0.5 * (g(x) + g(next)) * (next - x);
        x = next;
    }
    sum
}

#[test]
fn repeat_over_hundreds_of_periods_matches_the_cell_by_cell_sum() {
    // A separable texture, T(i, j) = A(i) B(j), whose bilinear reconstruction is a(s) b(t): over
    // an axis-aligned pixel its mean is the product of the 1D means. The quad repeats the 8 x 8
    // texture 1000.3 times across and 517.7 times down a 4 x 4 frame.
    let (w, h) = (4, 4);
    let a: Vec<f64> = (0..8).map(|i| 0.2 + 0.1 * f64::from((i * 5) % 8)).collect();
    let b: Vec<f64> = (0..8)
        .map(|j| 0.3 + 0.07 * f64::from((j * 3) % 8))
        .collect();
    let texture = float_texture(8, 8, |i, j| {
        [
            (a[i as usize] * b[j as usize]) as f32,
            a[i as usize] as f32,
            b[j as usize] as f32,
            1.0,
        ]
    });
    let s = sampler(AddressMode::Repeat);
    let (u1, v1) = (1000.3f32, 517.7f32);
    let vertices = quad(
        w,
        h,
        [0.0, 0.0, 4.0, 4.0],
        [[0., 0.], [u1, 0.], [u1, v1], [0., v1]],
    );
    let settings = RenderSettings::new(w, h);
    let e = render_exact(&settings, &[draw(&vertices, &QUAD, &texture, &s)], None).unwrap();
    assert!(e.exact.iter().all(|&x| x));
    let (su, sv) = (f64::from(u1) * 8.0 / 4.0, f64::from(v1) * 8.0 / 4.0);
    for j in 0..h {
        for i in 0..w {
            let (s0, s1) = (f64::from(i) * su - 0.5, f64::from(i + 1) * su - 0.5);
            let (t0, t1) = (f64::from(j) * sv - 0.5, f64::from(j + 1) * sv - 0.5);
            let ma = periodic_integral(&a, s0, s1) / (s1 - s0);
            let mb = periodic_integral(&b, t0, t1) / (t1 - t0);
            let c = at(&e, w, i, j);
            // The uvs are f32: the relative tolerance covers their rounding over 1000 periods.
            assert!(
                (f64::from(c[0]) - ma * mb).abs() < 2e-6,
                "({i}, {j}) {} vs {}",
                c[0],
                ma * mb
            );
            assert!((f64::from(c[1]) - ma).abs() < 2e-6, "({i}, {j})");
            assert!((f64::from(c[2]) - mb).abs() < 2e-6, "({i}, {j})");
        }
    }
}

/// Bilinear reconstruction of level 0 at `uv` in `f64`, Repeat.
fn bilinear_repeat(t: &Texture, uv: DVec2) -> [f64; 4] {
    let (w, h) = (t.width() as i64, t.height() as i64);
    let (x, y) = (uv.x * w as f64 - 0.5, uv.y * h as f64 - 0.5);
    let (i, j) = (x.floor(), y.floor());
    let (a, b) = (x - i, y - j);
    let texel = |di: i64, dj: i64| {
        let ii = (i as i64 + di).rem_euclid(w) as u32;
        let jj = (j as i64 + dj).rem_euclid(h) as u32;
        t.texel(0, ii, jj).unwrap().map(f64::from)
    };
    let (t00, t10, t01, t11) = (texel(0, 0), texel(1, 0), texel(0, 1), texel(1, 1));
    std::array::from_fn(|c| {
        (1.0 - b) * ((1.0 - a) * t00[c] + a * t10[c]) + b * ((1.0 - a) * t01[c] + a * t11[c])
    })
}

#[test]
fn a_perspective_checkerboard_matches_gauss_quadrature() {
    // The ground plane (a homography from screen to texture) with 8-texel checks: pixels whose
    // footprints span a few texels, against a product Gauss-Legendre rule (3 x 3 points) on
    // 256 x 256 sub-squares of each pixel, through the rasterizer's own homogeneous planes (the
    // homography the exact pass integrates). The integrand's kinks at texel centres limit the
    // quadrature: it moves by up to 1e-5 between 128 and 256 sub-squares, towards the exact
    // value; the tolerance is 5e-6.
    let (w, h) = (48, 27);
    let scene = Ground::with_texture(w, h, checker(64, 8));
    let s = sampler(AddressMode::Repeat);
    let settings = RenderSettings::new(w, h);
    let e = render_exact(&settings, &[scene.draw(&s)], None).unwrap();
    assert!(e.exact.iter().all(|&x| x));
    let setups = texel_raster::setup::setup_draws(&settings, &[scene.draw(&s)]).unwrap();
    // uv from the triangle whose barycentrics are all non-negative.
    let plane_uv = |x: f64, y: f64| {
        setups
            .iter()
            .find_map(|t| {
                let r = t.r.at(x, y);
                let l = t.q.map(|q| q.at(x, y) / r);
                l.iter().all(|&l| l >= -1e-12).then(|| {
                    let uv = t.indices.map(|k| scene.vertices[k as usize].uv.as_dvec2());
                    uv[0] * l[0] + uv[1] * l[1] + uv[2] * l[2]
                })
            })
            .unwrap()
    };
    const G: [(f64, f64); 3] = [
        (0.112_701_665_379_258_3, 5.0 / 18.0),
        (0.5, 8.0 / 18.0),
        (0.887_298_334_620_741_7, 5.0 / 18.0),
    ];
    let n = 256;
    let mut worst = 0.0f64;
    for (i, j) in [
        (0, 22),
        (5, 22),
        (7, 22),
        (20, 20),
        (31, 19),
        (44, 24),
        (13, 26),
        (27, 25),
    ] {
        let mut sum = [0.0; 4];
        for sy in 0..n {
            for sx in 0..n {
                for (gy, wy) in G {
                    for (gx, wx) in G {
                        let x = f64::from(i) + (f64::from(sx) + gx) / f64::from(n);
                        let y = f64::from(j) + (f64::from(sy) + gy) / f64::from(n);
                        let v = bilinear_repeat(&scene.texture, plane_uv(x, y));
                        for c in 0..4 {
                            sum[c] += v[c] * wx * wy;
                        }
                    }
                }
            }
        }
        let c = at(&e, w, i, j);
        for k in 0..4 {
            let q = sum[k] / f64::from(n * n);
            worst = worst.max((f64::from(c[k]) - q).abs());
        }
    }
    eprintln!("largest difference from the quadrature: {worst:.2e}");
    assert!(worst < 5e-6, "{worst}");
}

#[test]
fn pixels_it_cannot_integrate_are_sampled_and_marked() {
    // The ground (exact) under a triangle with three vertex colours (not constant over the
    // triangle: sampled), and two triangles that cross each other inside some pixels.
    let (w, h) = (48, 27);
    let scene = Ground::with_texture(w, h, checker(64, 8));
    let s = sampler(AddressMode::Repeat);
    let white = float_texture(1, 1, |_, _| [1.0; 4]);
    let mut coloured = vec![
        screen_vertex(4.0, 20.0, w, h),
        screen_vertex(14.0, 20.0, w, h),
        screen_vertex(9.0, 24.0, w, h),
    ];
    let colours = [
        Vec4::new(1.0, 0.0, 0.0, 1.0),
        Vec4::Y + Vec4::W,
        Vec4::Z + Vec4::W,
    ];
    for (v, c) in coloured.iter_mut().zip(colours) {
        v.color = c;
        v.position.z = -0.5;
    }
    // Two triangles whose depths cross along x = 30.5 (one tilts towards the eye, one away).
    let mut crossing = vec![
        screen_vertex(26.0, 2.0, w, h),
        screen_vertex(35.0, 2.0, w, h),
        screen_vertex(30.5, 10.0, w, h),
        screen_vertex(26.0, 3.0, w, h),
        screen_vertex(35.0, 3.0, w, h),
        screen_vertex(30.5, 11.0, w, h),
    ];
    for (k, z) in [-0.9, 0.1, -0.4, 0.1, -0.9, -0.4].into_iter().enumerate() {
        crossing[k].position.z = z;
    }
    let tri = [[0u32, 2, 1]];
    let pair = [[0u32, 2, 1], [3, 5, 4]];
    let draws = [
        scene.draw(&s),
        draw(&coloured, &tri, &white, &s),
        draw(&crossing, &pair, &white, &s),
    ];
    let settings = RenderSettings::new(w, h);
    let e = render_exact(&settings, &draws, None).unwrap();
    let exact = |i: u32, j: u32| e.exact[(j * w + i) as usize];
    // Inside the coloured triangle and on its silhouette over the ground: sampled.
    assert!(!exact(9, 21) && !exact(4, 20) && !exact(13, 20));
    // The ground beside it, and the sky: exact.
    assert!(exact(20, 22) && exact(2, 24) && exact(20, 0));
    // Where the two white triangles cross: sampled; where only one covers, or one is in front
    // over the whole pixel: exact.
    assert!(!exact(30, 4));
    assert!(exact(27, 2) && exact(33, 4));
    // Through the converging reference: exact pixels have no error and no samples, the others are
    // the sampled reference's own pixels, bit for bit.
    let plan = ReferencePlan::new(16, 16, 0.5, true, 7).unwrap();
    let sampled = render_reference_adaptive(&settings, &draws, &plan, None, None).unwrap();
    let mixed =
        render_reference_adaptive(&settings, &draws, &plan.with_exact(true), None, None).unwrap();
    for k in 0..(w * h) as usize {
        if e.exact[k] {
            assert!(mixed.exact[k] && mixed.spp[k] == 0 && mixed.std_error[k] == [0.0; 4]);
            assert_eq!(mixed.frame.color[k], e.color[k]);
            assert!(mixed.display_half_width[k] < 1e-5);
        } else {
            assert!(!mixed.exact[k] && mixed.spp[k] == 16);
            assert_eq!(mixed.frame.color[k], sampled.frame.color[k], "pixel {k}");
            assert_eq!(mixed.std_error[k], sampled.std_error[k]);
        }
    }
    assert!(sampled.exact.iter().all(|&x| !x));
}

#[test]
fn absurd_texture_coordinates_are_sampled_not_hung_on() {
    // uvs of 1e12 periods across a 4 x 4 frame of a texture that bends at every texel: the
    // preimage is beyond what f64 moments resolve and would cut the boundary at 1e13 knots, so
    // every pixel falls back to sampling (and says so) instead of running for ever.
    let (w, h) = (4, 4);
    let texture = float_texture(8, 8, |i, j| {
        [((i * 7 + j * 3) % 5) as f32 / 4.0, 0.5, 0.5, 1.0]
    });
    let s = sampler(AddressMode::Repeat);
    let big = 1e12f32;
    let vertices = quad(
        w,
        h,
        [0.0, 0.0, 4.0, 4.0],
        [[0., 0.], [big, 0.], [big, big], [0., big]],
    );
    let settings = RenderSettings::new(w, h);
    let e = render_exact(&settings, &[draw(&vertices, &QUAD, &texture, &s)], None).unwrap();
    assert!(e.exact.iter().all(|&x| !x));
}
