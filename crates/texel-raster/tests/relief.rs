//! Height maps: bump mapping and parallax occlusion mapping against the analytic surfaces they
//! stand for, and projected-space NDF filtering on a surface whose normal does not vary.

mod lit_plane;

use glam::{Mat4, Vec3};
use lit_plane::{plane, view, H, PLANE_TRIANGLES, W};
use texel_raster::material::{radiance, Surface};
use texel_raster::{
    render, ChannelInput, Displacement, DrawCall, Light, Material, RenderSettings, SpecularAa,
    TextureInput, Vertex, MAX_LIGHTS,
};
use texel_texture::{AddressMode, Filter, Format, Limits, Sampler, SamplerDescriptor, Texture};

/// The ray from `eye` through pixel `(i, j)`'s centre (unit direction).
fn ray(m: Mat4, eye: Vec3, i: u32, j: u32) -> Vec3 {
    let x = (i as f32 + 0.5) / W as f32 * 2.0 - 1.0;
    let y = 1.0 - (j as f32 + 0.5) / H as f32 * 2.0;
    (m.inverse().project_point3(Vec3::new(x, y, 1.0)) - eye).normalize()
}

/// A 64x64 float texture holding `f(u, v)` at texel centres, in every channel.
fn float_map(f: impl Fn(f32, f32) -> f32) -> Texture {
    Texture::from_fn(64, 64, Format::Rgba32Float, &Limits::default(), |i, j| {
        let v = f((i as f32 + 0.5) / 64.0, (j as f32 + 0.5) / 64.0);
        [v, v, v, 1.0]
    })
    .unwrap()
}

fn trilinear_clamped() -> Sampler {
    let d = SamplerDescriptor::from(Filter::Trilinear);
    Sampler::new(d.with_address_mode(AddressMode::ClampToEdge)).unwrap()
}

/// A height map read through `sampler`, red channel.
fn heights_of<'a>(texture: &'a Texture, sampler: &'a Sampler) -> ChannelInput<'a> {
    ChannelInput {
        input: TextureInput { texture, sampler },
        channel: 0,
    }
}

/// A material with height map `heights` (if any) shaping the surface as `displacement`.
fn relief_material<'a>(
    heights: Option<&'a Texture>,
    sampler: &'a Sampler,
    height_scale: f32,
    displacement: Displacement,
) -> Material<'a> {
    Material {
        roughness: 0.4,
        height_map: heights.map(|t| heights_of(t, sampler)),
        height_scale,
        displacement,
        ..Material::default()
    }
}

/// The plane with `texture`, shaded with `material`.
fn plane_draw<'a>(
    vertices: &'a [Vertex],
    texture: &'a Texture,
    sampler: &'a Sampler,
    clip_from_world: Mat4,
    material: Material<'a>,
) -> DrawCall<'a> {
    DrawCall {
        vertices,
        triangles: &PLANE_TRIANGLES,
        texture,
        sampler,
        clip_from_world,
        material: Some(material),
        uv_mapping: None,
    }
}

fn lit(light: Light) -> RenderSettings<'static> {
    let mut lights = [None; MAX_LIGHTS];
    lights[0] = Some(light);
    RenderSettings {
        lights,
        ..RenderSettings::new(W, H)
    }
}

/// Heights rising linearly along u, `h = u`: the bumped surface is the plane `z = s (u - 1)`,
/// whose normal is `(-s / 2, 0, 1)` (2 world units per unit of u). Every pixel inside the square
/// shades with that normal, for every footprint-following step.
#[test]
fn bump_mapping_a_ramp_gives_the_tilted_planes_normal() {
    let heights = float_map(|u, _| u);
    let white = float_map(|_, _| 1.0);
    let sampler = trilinear_clamped();
    let vertices = plane();
    let (m, eye) = view();
    let light = Light::Directional {
        direction: Vec3::new(0.6, 0.3, 1.0),
        intensity: Vec3::splat(3.0),
    };
    for s in [0.2f32, 1.0] {
        let material = relief_material(Some(&heights), &sampler, s, Displacement::Bump);
        let draw = plane_draw(&vertices, &white, &sampler, m, material);
        let frame = render(&lit(light), &[draw]).unwrap();
        // The reference's sub-samples bump-map from level 0 with their own small step: the
        // same plane's normal (1 sample per pixel at the centre, so the same positions).
        let reference =
            texel_raster::reference::render_reference(&lit(light), &[draw], 1, 0, None).unwrap();
        let normal = Vec3::new(-s / 2.0, 0.0, 1.0).normalize();
        for (i, j) in [(48, 32), (35, 25), (60, 40)] {
            let k = frame.index(i, j);
            assert!(frame.covered(k));
            let (a, b) = (
                Vec3::from_slice(&frame.color[k][..3]),
                Vec3::from_slice(&reference.color[k][..3]),
            );
            assert!(
                (a - b).abs().max_element() < 0.02 * a.max_element(),
                "reference {b} vs {a}"
            );
            let d = ray(m, eye, i, j);
            let surface = Surface {
                base: Vec3::ONE,
                roughness: 0.4,
                metallic: 0.0,
                normal,
                diffuse_normal: normal,
                position: eye + d * (-eye.z / d.z),
                occlusion: 1.0,
                spread: None,
            };
            let want = radiance(&surface, eye, &[light], false);
            let got = Vec3::from_slice(&frame.color[k][..3]);
            assert!(
                (got - want).abs().max_element() < 2e-3 * want.max_element(),
                "s {s} ({i}, {j}): got {got}, want {want}"
            );
        }
    }
}

/// Constant heights `h = 0.5` put the relief flat, `s / 2` below the polygon: parallax occlusion
/// mapping must read the colour where the view ray meets that plane. The colour is `u` and only
/// ambient light shines, so a pixel shows `A (u + 0.04)` at the hit's `u`.
#[test]
fn parallax_reads_where_the_ray_meets_the_relief() {
    let heights = float_map(|_, _| 0.5);
    let ramp = float_map(|u, _| u);
    let sampler = trilinear_clamped();
    let vertices = plane();
    let (m, eye) = view();
    let s = 0.4f32;
    let material = relief_material(Some(&heights), &sampler, s, Displacement::Pom);
    let draw = plane_draw(&vertices, &ramp, &sampler, m, material);
    let ambient = Light::Ambient {
        intensity: Vec3::ONE,
    };
    let frame = render(&lit(ambient), &[draw]).unwrap();
    let flat = render(
        &lit(ambient),
        &[DrawCall {
            material: Some(Material {
                displacement: Displacement::None,
                ..material
            }),
            ..draw
        }],
    )
    .unwrap();
    let mut moved = 0;
    for (i, j) in [(48, 32), (35, 25), (60, 40), (30, 40)] {
        let k = frame.index(i, j);
        assert!(frame.covered(k));
        let d = ray(m, eye, i, j);
        let q = eye + d * ((-s / 2.0 - eye.z) / d.z);
        let u = (q.x + 1.0) / 2.0;
        let got = frame.color[k][0];
        let want = u + 0.04;
        assert!(
            (got - want).abs() < 2e-3,
            "({i}, {j}): got {got}, want {want}"
        );
        // Without parallax the polygon's own u shows.
        let p = eye + d * (-eye.z / d.z);
        assert!((flat.color[k][0] - ((p.x + 1.0) / 2.0 + 0.04)).abs() < 2e-3);
        moved += usize::from((got - flat.color[k][0]).abs() > 0.01);
    }
    assert!(moved >= 3, "parallax moved only {moved} of 4 pixels");
}

/// Projected-space NDF filtering widens the lobe only where the normal changes from pixel to
/// pixel: on a flat plane without maps it is the unfiltered image bit for bit; over a bumpy height
/// map it changes the highlight.
#[test]
fn projected_filtering_widens_only_where_the_normal_varies() {
    let white = float_map(|_, _| 1.0);
    let bumps = float_map(|u, v| {
        0.5 + 0.5
            * (u * 40.0 * std::f32::consts::TAU).sin()
            * (v * 40.0 * std::f32::consts::TAU).sin()
    });
    let sampler = trilinear_clamped();
    let vertices = plane();
    let (m, _) = view();
    let light = Light::Directional {
        direction: Vec3::new(-0.4, -0.3, 3.0),
        intensity: Vec3::splat(3.0),
    };
    let frame = |aa: SpecularAa, height: Option<&Texture>| {
        let shape = if height.is_some() {
            Displacement::Bump
        } else {
            Displacement::None
        };
        let material = Material {
            roughness: 0.2,
            specular_aa: aa,
            ..relief_material(height, &sampler, 0.02, shape)
        };
        render(
            &lit(light),
            &[plane_draw(&vertices, &white, &sampler, m, material)],
        )
        .unwrap()
    };
    assert_eq!(
        frame(SpecularAa::Projected, None).color,
        frame(SpecularAa::None, None).color
    );
    let (plain, filtered) = (
        frame(SpecularAa::None, Some(&bumps)),
        frame(SpecularAa::Projected, Some(&bumps)),
    );
    let peak = |f: &texel_raster::Frame| f.color.iter().map(|c| c[0]).fold(0.0f32, f32::max);
    // A wider lobe has a lower peak.
    assert!(
        peak(&filtered) < 0.9 * peak(&plain),
        "{} vs {}",
        peak(&filtered),
        peak(&plain)
    );
}

/// A tangent-space normal map (`rgb = (n + 1) / 2`, linear) of an egg-crate with `cells` bumps
/// per side whose slopes reach `slope`: `h = sin(2 pi c u) sin(2 pi c v) slope / (2 pi c)`.
fn egg_crate_normals(size: u32, cells: f32, slope: f32) -> Texture {
    let k = std::f32::consts::TAU * cells;
    Texture::from_fn(
        size,
        size,
        Format::Rgba32Float,
        &Limits::default(),
        |i, j| {
            let (u, v) = (
                (i as f32 + 0.5) / size as f32,
                (j as f32 + 0.5) / size as f32,
            );
            let (sx, sy) = (
                slope * (k * u).cos() * (k * v).sin(),
                slope * (k * u).sin() * (k * v).cos(),
            );
            let n = Vec3::new(-sx, sy, 1.0).normalize();
            [(n.x + 1.0) / 2.0, (n.y + 1.0) / 2.0, (n.z + 1.0) / 2.0, 1.0]
        },
    )
    .unwrap()
}

/// Adaptive shading supersampling ([`Material::shading_samples`]) on a glossy plane whose normal
/// map's bumps are several pixels wide (partly resolved, so one shading sample per pixel
/// point-samples highlights narrower than a pixel): the frame comes close to the same view
/// rendered at 8 x 8 the resolution and averaged in linear light (the pixel's true mean under a
/// box filter), where the single-sample frame does not (measured, linear radiance whose
/// highlights reach 6: mean error 0.0014 against 0.116, worst pixel 0.25 against 5.9; the rule
/// asks for more than 8 sub-samples per axis here, so the grid is the fine frame's); and where
/// the normal does not turn (no map) nothing changes, bit for bit.
#[test]
fn shading_sub_samples_integrate_highlights_a_pixel_cannot_point_sample() {
    let white = float_map(|_, _| 1.0);
    let bumps = egg_crate_normals(256, 8.0, 0.6);
    let sampler = trilinear_clamped();
    let vertices = plane();
    let (m, _) = view();
    let light = Light::Directional {
        direction: Vec3::new(-0.2, 0.5, 1.0),
        intensity: Vec3::splat(3.0),
    };
    let frame = |samples: u32, normals: Option<&Texture>, scale: u32| {
        let material = Material {
            roughness: 0.2,
            normal_map: normals.map(|texture| TextureInput {
                texture,
                sampler: &sampler,
            }),
            shading_samples: samples,
            ..Material::default()
        };
        let settings = RenderSettings {
            width: W * scale,
            height: H * scale,
            ..lit(light)
        };
        render(
            &settings,
            &[plane_draw(&vertices, &white, &sampler, m, material)],
        )
        .unwrap()
    };
    assert_eq!(frame(8, None, 1).color, frame(1, None, 1).color);
    let (one, grid, fine) = (
        frame(1, Some(&bumps), 1),
        frame(8, Some(&bumps), 1),
        frame(1, Some(&bumps), 8),
    );
    // The fine frame's 8 x 8 block means, over pixels whose block is wholly covered.
    let mut errors = (Vec::new(), Vec::new());
    for j in 0..H {
        for i in 0..W {
            let mut sum = Vec3::ZERO;
            let mut covered = true;
            for b in 0..8 {
                for a in 0..8 {
                    let k = ((j * 8 + b) * W * 8 + i * 8 + a) as usize;
                    covered &= fine.depth[k].is_finite();
                    sum += Vec3::from_slice(&fine.color[k][..3]);
                }
            }
            if !covered {
                continue;
            }
            let truth = sum / 64.0;
            let k = (j * W + i) as usize;
            let error = |f: &texel_raster::Frame| {
                (Vec3::from_slice(&f.color[k][..3]) - truth)
                    .abs()
                    .max_element()
            };
            errors.0.push(error(&one));
            errors.1.push(error(&grid));
        }
    }
    assert!(errors.0.len() > 1000, "{}", errors.0.len());
    let mean = |e: &[f32]| e.iter().sum::<f32>() / e.len() as f32;
    let worst = |e: &[f32]| e.iter().fold(0.0f32, |a, &b| a.max(b));
    let (m1, m8) = (mean(&errors.0), mean(&errors.1));
    let (w1, w8) = (worst(&errors.0), worst(&errors.1));
    eprintln!("mean error {m8} (one sample: {m1}), worst {w8} (one sample: {w1})");
    assert!(
        m8 < 0.05 * m1 && w8 < 0.1 * w1,
        "{m8} vs {m1}, {w8} vs {w1}"
    );
}
