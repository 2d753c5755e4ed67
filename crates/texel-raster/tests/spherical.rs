//! Spherical mappings of a surface (`UvMapping`): the per-pixel uv is the projection of the pixel's
//! surface point with its exact derivatives, no seam appears in the level, the reference evaluates
//! the projection, and per-pixel evaluation beats per-vertex interpolation against it.

use glam::{DVec2, DVec3, Mat4, Vec2, Vec3};
use texel_raster::{
    camera, render, render_reference, Derivatives, DrawCall, Frame, RenderSettings, UvEvaluation,
    UvMapping, Vertex,
};
use texel_texture::mapping::sphere::SurfaceProjection;
use texel_texture::{AddressMode, Filter, Format, Limits, Sampler, SamplerDescriptor, Texture};

const PROJECTIONS: [SurfaceProjection; 2] =
    [SurfaceProjection::Equirect, SurfaceProjection::MERCATOR];

/// A sphere centre away from the origin, so the mapping's centre is really used.
const CENTRE: Vec3 = Vec3::new(0.3, -0.2, 0.1);

/// A unit sphere about [`CENTRE`], `segments x rings`, uv = `projection` at each vertex, with the
/// seam column duplicated at u = 1 and a pole vertex per column (as the built-in sphere).
fn sphere(
    projection: SurfaceProjection,
    segments: u32,
    rings: u32,
) -> (Vec<Vertex>, Vec<[u32; 3]>) {
    let mut vertices = Vec::new();
    for r in 0..=rings {
        let theta = std::f64::consts::PI * f64::from(r) / f64::from(rings);
        for s in 0..=segments {
            let phi = 2.0 * std::f64::consts::PI * f64::from(s) / f64::from(segments);
            let d = DVec3::new(
                theta.sin() * phi.sin(),
                theta.cos(),
                theta.sin() * phi.cos(),
            );
            let v = projection.uv(DVec3::new(theta.sin(), theta.cos(), 0.0)).y;
            let mut vert = Vertex::new(
                d.as_vec3() + CENTRE,
                Vec2::new(s as f32 / segments as f32, v as f32),
            );
            vert.normal = d.as_vec3();
            vertices.push(vert);
        }
    }
    let row = segments + 1;
    let mut triangles = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * row + s, (r + 1) * row + s);
            if r != 0 {
                triangles.push([a, b, a + 1]);
            }
            if r != rings - 1 {
                triangles.push([a + 1, b, b + 1]);
            }
        }
    }
    (vertices, triangles)
}

/// Looking at the sphere from `+z` and a little above: the seam (`u = 0`, the meridian through
/// `+z`) runs down the middle of the frame.
fn view() -> Mat4 {
    let eye = CENTRE + Vec3::new(0.0, 0.8, 2.6);
    camera::perspective(50f32.to_radians(), 1.0, 0.1, 100.0) * camera::look_at(eye, CENTRE, Vec3::Y)
}

/// Horizontal bands `height / 16` texels high, alternately dark and light, times a faint ramp in
/// `u` (so `u` matters too): where `v` lands shows at once.
fn bands(width: u32, height: u32) -> Texture {
    Texture::from_fn(
        width,
        height,
        Format::Rgba32Float,
        &Limits::default(),
        |i, j| {
            let band = if (j * 16 / height).is_multiple_of(2) {
                0.1
            } else {
                0.9
            };
            let ramp = 0.8 + 0.2 * (i as f32 + 0.5) / width as f32;
            [band * ramp, band, band * (1.8 - ramp), 1.0]
        },
    )
    .unwrap()
}

fn trilinear() -> Sampler {
    let d = SamplerDescriptor::from(Filter::Trilinear);
    Sampler::new(SamplerDescriptor {
        address_mode_u: AddressMode::Repeat,
        address_mode_v: AddressMode::ClampToEdge,
        ..d
    })
    .unwrap()
}

fn draw<'a>(
    mesh: &'a (Vec<Vertex>, Vec<[u32; 3]>),
    texture: &'a Texture,
    sampler: &'a Sampler,
    clip: Mat4,
    mapping: Option<UvMapping>,
) -> DrawCall<'a> {
    DrawCall {
        vertices: &mesh.0,
        triangles: &mesh.1,
        texture,
        sampler,
        clip_from_world: clip,
        material: None,
        uv_mapping: mapping,
    }
}

fn mapping(projection: SurfaceProjection, evaluation: UvEvaluation) -> Option<UvMapping> {
    Some(UvMapping {
        projection,
        centre: CENTRE,
        evaluation,
    })
}

/// The world point where the ray through `(x, y)` (pixel coordinates of an `n x n` frame) meets
/// the plane through `p0` with normal `normal`.
fn ray_hit(clip: Mat4, n: u32, x: f64, y: f64, p0: DVec3, normal: DVec3) -> DVec3 {
    let inv = clip.as_dmat4().inverse();
    let ndc = DVec2::new(2.0 * x / f64::from(n) - 1.0, 1.0 - 2.0 * y / f64::from(n));
    let a = inv.project_point3(ndc.extend(-0.5));
    let b = inv.project_point3(ndc.extend(0.5));
    let t = (p0 - a).dot(normal) / (b - a).dot(normal);
    a + (b - a) * t
}

/// Distance between two `u`s on the circle of period 1.
fn du(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(1.0);
    d.min(1.0 - d)
}

#[test]
fn per_pixel_uv_is_the_projection_of_the_surface_point_with_exact_derivatives() {
    // One flat triangle in front of the sphere's centre, straddling the seam and reaching 60
    // degrees north: each pixel's point is where its ray meets the plane, its uv the projection of
    // that point's direction, its derivatives the change of that uv per pixel.
    let n = 48;
    let clip = view();
    let corners = [
        Vec3::new(-0.9, -0.6, 0.6),
        Vec3::new(0.9, -0.6, 0.6),
        Vec3::new(0.0, 1.2, 0.2),
    ]
    .map(|p| p + CENTRE);
    let mesh = (
        corners
            .iter()
            .map(|&p| Vertex::new(p, Vec2::ZERO))
            .collect::<Vec<_>>(),
        vec![[0, 1, 2]],
    );
    let (p0, e1, e2) = (
        corners[0].as_dvec3(),
        (corners[1] - corners[0]).as_dvec3(),
        (corners[2] - corners[0]).as_dvec3(),
    );
    let normal = e1.cross(e2);
    let texture = bands(256, 256);
    let sampler = trilinear();
    for projection in PROJECTIONS {
        for derivatives in [Derivatives::Analytic, Derivatives::Quad] {
            let m = mapping(projection, UvEvaluation::PerPixel);
            let mut settings = RenderSettings::new(n, n);
            settings.capture_footprints = true;
            settings.derivatives = derivatives;
            let frame = render(&settings, &[draw(&mesh, &texture, &sampler, clip, m)]).unwrap();
            let exact = |x: f64, y: f64| {
                projection.uv(ray_hit(clip, n, x, y, p0, normal) - CENTRE.as_dvec3())
            };
            let (mut covered, mut wrapped) = (0, 0);
            for j in 0..n {
                for i in 0..n {
                    let k = frame.index(i, j);
                    if frame.depth[k] == f32::INFINITY {
                        continue;
                    }
                    covered += 1;
                    let (x, y) = (f64::from(i) + 0.5, f64::from(j) + 0.5);
                    let want = exact(x, y);
                    let fp = &frame.footprints[k];
                    assert!(
                        du(f64::from(fp.u), want.x) < 2e-6
                            && (f64::from(fp.v) - want.y).abs() < 2e-6,
                        "{projection:?} ({i}, {j}): ({}, {}) vs {want}",
                        fp.u,
                        fp.v
                    );
                    // The derivatives: analytic ones against central differences of the exact
                    // uv; the quad's are the Jacobian at the pixel applied to the quad's
                    // position difference, so compare them against a one-pixel difference.
                    let h = if derivatives == Derivatives::Analytic {
                        1e-3
                    } else {
                        0.5
                    };
                    let diff = |a: DVec2, b: DVec2| {
                        let mut d = (a - b) / (2.0 * h);
                        d.x = (d.x + 0.5 / (2.0 * h)).rem_euclid(1.0 / (2.0 * h)) - 0.5 / (2.0 * h);
                        d
                    };
                    let ddx = diff(exact(x + h, y), exact(x - h, y));
                    let ddy = diff(exact(x, y + h), exact(x, y - h));
                    let got_x = DVec2::new(f64::from(fp.dudx), f64::from(fp.dvdx));
                    let got_y = DVec2::new(f64::from(fp.dudy), f64::from(fp.dvdy));
                    let tol = if derivatives == Derivatives::Analytic {
                        1e-4
                    } else {
                        0.1
                    };
                    for (got, want) in [(got_x, ddx), (got_y, ddy)] {
                        assert!(
                            (got - want).length() <= tol * want.length() + 1e-7,
                            "{projection:?} {derivatives:?} ({i}, {j}): {got} vs {want}"
                        );
                    }
                    if (f64::from(fp.u) - 0.5).abs() > 0.45 {
                        wrapped += 1;
                    }
                }
            }
            assert!(covered > 300 && wrapped > 10, "{covered} {wrapped}");
        }
    }
}

#[test]
fn no_seam_pixel_reads_a_level_more_than_one_above_its_neighbours() {
    // The seam faces the camera. Differencing u across it jumps by about 1 (a whole texture
    // width: the coarsest level); the Jacobian of the projection does not jump at all.
    let n = 96;
    let clip = view();
    let texture = bands(512, 512);
    let sampler = trilinear();
    for projection in PROJECTIONS {
        let mesh = sphere(projection, 32, 16);
        for derivatives in [Derivatives::Analytic, Derivatives::Quad] {
            let m = mapping(projection, UvEvaluation::PerPixel);
            let mut settings = RenderSettings::new(n, n);
            settings.capture_footprints = true;
            settings.derivatives = derivatives;
            let frame = render(&settings, &[draw(&mesh, &texture, &sampler, clip, m)]).unwrap();
            let covered = |i: u32, j: u32| frame.depth[frame.index(i, j)] < f32::INFINITY;
            let fp = |i: u32, j: u32| frame.footprints[frame.index(i, j)];
            let lod = |i: u32, j: u32| sampler.lod(&texture, &fp(i, j));
            let (mut pairs, mut naive_jumps) = (0, 0);
            for j in 0..n {
                for i in 0..n - 1 {
                    if !(covered(i, j) && covered(i + 1, j)) {
                        continue;
                    }
                    let (a, b) = (fp(i, j), fp(i + 1, j));
                    if (a.u - b.u).abs() < 0.5 {
                        continue;
                    }
                    // A pair of pixels either side of the seam, away from the poles (where u is
                    // undefined and the level rises to the coarsest, seam or not).
                    let lat = projection
                        .direction(DVec2::new(f64::from(a.u), f64::from(a.v)))
                        .y
                        .asin();
                    if lat.abs() > 60f64.to_radians() {
                        continue;
                    }
                    pairs += 1;
                    let (la, lb) = (lod(i, j), lod(i + 1, j));
                    // Its neighbours along the row, across the seam and away from it (the
                    // level changes down the column anyway, fastest in 2x2 quads near the limb).
                    for (k, l) in [(i, la), (i + 1, lb)] {
                        for (ni, nj) in [(k.wrapping_sub(1), j), (k + 1, j)] {
                            if ni < n && nj < n && covered(ni, nj) {
                                let ln = lod(ni, nj);
                                assert!(
                                    l <= ln + 1.0,
                                    "{projection:?} {derivatives:?} seam ({k}, {j}) level {l}, \
                                     neighbour ({ni}, {nj}) {ln}"
                                );
                            }
                        }
                    }
                    // What differencing u would have given there: the coarsest levels.
                    let naive = texel_texture::Footprint {
                        dudx: b.u - a.u,
                        ..a
                    };
                    if sampler.lod(&texture, &naive) > la + 4.0 {
                        naive_jumps += 1;
                    }
                }
            }
            assert!(
                pairs >= 20,
                "{projection:?}: the seam is in view ({pairs} pairs)"
            );
            assert_eq!(
                naive_jumps, pairs,
                "differencing u would jump at every seam pixel"
            );
        }
    }
}

/// Mean squared difference of two frames' colours over the pixels inside `a`'s silhouette (whose
/// 3x3 neighbourhood `a` covers: the reference's edge pixels mix in the background).
fn mse(a: &Frame, b: &Frame) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    let inside = |i: u32, j: u32| a.depth[a.index(i, j)] < f32::INFINITY;
    for j in 1..a.height - 1 {
        for i in 1..a.width - 1 {
            if (0..9).all(|k| inside(i + k % 3 - 1, j + k / 3 - 1)) {
                let k = a.index(i, j);
                for c in 0..3 {
                    sum += f64::from(a.color[k][c] - b.color[k][c]).powi(2);
                }
                count += 3;
            }
        }
    }
    sum / count.max(1) as f64
}

#[test]
fn the_reference_evaluates_the_projection_and_per_pixel_is_closer_to_it() {
    // A coarse sphere (16 x 8: 22.5 degree rings), where interpolating Mercator's v linearly
    // between rings puts the bands in the wrong place; the reference evaluates the projection at
    // every sample whichever way the draw asks for.
    let n = 128;
    let clip = view();
    let texture = bands(256, 256);
    let sampler = trilinear();
    let projection = SurfaceProjection::MERCATOR;
    let mesh = sphere(projection, 16, 8);
    let settings = RenderSettings::new(n, n);
    let frames = [UvEvaluation::PerVertex, UvEvaluation::PerPixel].map(|e| {
        let d = [draw(
            &mesh,
            &texture,
            &sampler,
            clip,
            mapping(projection, e),
        )];
        (
            render(&settings, &d).unwrap(),
            render_reference(&settings, &d, 4, 7, None).unwrap(),
        )
    });
    let [(vertex, ref_v), (pixel, ref_p)] = &frames;
    assert_eq!(ref_v.color, ref_p.color, "one ground truth");
    let (e_vertex, e_pixel) = (mse(vertex, ref_p), mse(pixel, ref_p));
    assert!(
        e_pixel * 4.0 < e_vertex,
        "per pixel {e_pixel:.2e}, per vertex {e_vertex:.2e}"
    );
    // Without a mapping the reference interpolates the vertices' uv: then it agrees with the
    // per-vertex render instead.
    let plain = [draw(&mesh, &texture, &sampler, clip, None)];
    let ref_plain = render_reference(&settings, &plain, 4, 7, None).unwrap();
    assert!(mse(vertex, &ref_plain) * 4.0 < e_vertex);
}
