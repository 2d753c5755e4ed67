//! Environment maps: the prefiltered pyramid and irradiance against analytic integrals, the
//! background and the light of a constant environment, and the seam's footprints.

use glam::{DVec3, Mat4, Vec2, Vec3, Vec4};
use texel_raster::environment::{equirect_descriptor, roughness_lod};
use texel_raster::{
    render, render_reference, DrawCall, Environment, EnvironmentMaps, Material, RenderSettings,
    Vertex,
};
use texel_texture::{Footprint, Format, Limits, Sampler, SamplerDescriptor, Texture};

/// A `w x w/2` float equirectangular map holding `f(direction)` at texel centres.
fn map(w: u32, f: impl Fn(DVec3) -> [f32; 3]) -> Texture {
    Texture::from_fn(w, w / 2, Format::Rgba32Float, &Limits::default(), |i, j| {
        let uv = glam::DVec2::new(
            (f64::from(i) + 0.5) / f64::from(w),
            (f64::from(j) + 0.5) / f64::from(w / 2),
        );
        let c = f(texel_raster::environment::equirect_direction(uv));
        [c[0], c[1], c[2], 1.0]
    })
    .unwrap()
}

fn maps(t: Texture) -> EnvironmentMaps {
    EnvironmentMaps::new(t, &Limits::default()).unwrap()
}

fn sampler(lab: u8) -> Sampler {
    Sampler::new(equirect_descriptor(
        SamplerDescriptor::lab_mode(lab).unwrap(),
    ))
    .unwrap()
}

fn env<'a>(maps: &'a EnvironmentMaps, s: &'a Sampler, clip: Mat4) -> Environment<'a> {
    Environment {
        maps,
        sampler: s,
        intensity: Vec3::splat(2.0),
        background: true,
        clip_from_world: clip,
    }
}

/// A camera at the origin looking along `forward`, 90 degrees vertical field, square frame.
fn camera(forward: Vec3) -> Mat4 {
    Mat4::perspective_rh(90f32.to_radians(), 1.0, 0.1, 100.0)
        * Mat4::look_at_rh(Vec3::ZERO, forward, Vec3::Y)
}

#[test]
fn a_constant_map_prefilters_and_integrates_to_itself() {
    let m = maps(map(128, |_| [0.5, 1.0, 2.0]));
    // Every level of the glossy pyramid is the constant (the lobe's weights are normalised).
    for (k, l) in m.glossy.levels().iter().enumerate() {
        for (i, j) in [
            (0, 0),
            (l.width / 2, l.height / 2),
            (l.width - 1, l.height - 1),
        ] {
            let t = m.glossy.texel(k, i, j).unwrap();
            for (c, want) in t.iter().zip([0.5, 1.0, 2.0]) {
                assert!(
                    (c - want).abs() < 1e-4 * want,
                    "level {k} ({i}, {j}): {t:?}"
                );
            }
        }
    }
    // E / pi of a constant radiance L is L for every normal (the cosine integrates to pi).
    let l = m.irradiance.levels()[0];
    for j in 0..l.height {
        for i in 0..l.width {
            let e = m.irradiance.texel(0, i, j).unwrap();
            assert!((e[1] - 1.0).abs() < 0.01, "({i}, {j}): {e:?}");
        }
    }
}

#[test]
fn irradiance_of_a_bright_upper_hemisphere_follows_the_cosine_law() {
    // L = 1 above the horizon, 0 below: E / pi = (1 + n.y) / 2 exactly.
    let m = maps(map(256, |d| if d.y > 0.0 { [1.0; 3] } else { [0.0; 3] }));
    let s = sampler(4);
    let e = env(&m, &s, Mat4::IDENTITY);
    for n in [
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::X,
        DVec3::new(0.3, 0.8, -0.5).normalize(),
    ] {
        let (got, _) = e.irradiance(n, false);
        let want = 2.0 * (1.0 + n.y) / 2.0; // times the intensity 2
        assert!(
            (f64::from(got.x) - want).abs() < 0.03,
            "{n}: {got} vs {want}"
        );
    }
}

#[test]
fn the_glossy_pyramid_blurs_with_roughness() {
    // A map with one bright band: the prefiltered levels spread it, ever wider.
    let m = maps(map(256, |d| {
        if d.y.abs() < 0.05 {
            [10.0; 3]
        } else {
            [0.0; 3]
        }
    }));
    // Straight up, 60 degrees from the band: dark at level 0 and for a smooth lobe, lit by a
    // rough one.
    let up = |level: usize| {
        let l = m.glossy.levels()[level];
        m.glossy.texel(level, l.width / 2, l.height / 6).unwrap()[0]
    };
    assert_eq!(up(0), 0.0);
    let last = m.glossy.levels().len() - 1;
    assert!(up(last - 1) > 0.1, "{}", up(last - 1));
    assert!(roughness_lod(0.0, 256) < 0.0 && roughness_lod(1.0, 256) > 5.0);
}

#[test]
fn the_background_is_the_map_along_each_camera_ray() {
    let m = maps(map(64, |d| [d.x as f32 * 0.5 + 0.5, 0.25, 0.75]));
    let s = sampler(2);
    let clip = camera(Vec3::new(0.3, 0.2, -1.0));
    let mut settings = RenderSettings::new(32, 32);
    settings.environment = Some(env(&m, &s, clip));
    let frame = render(&settings, &[]).unwrap();
    let reference = render_reference(&settings, &[], 2, 1, None).unwrap();
    let inv = clip.inverse();
    for (i, j) in [(0, 0), (16, 16), (31, 5)] {
        let c = frame.color[frame.index(i, j)];
        let x = (i as f32 + 0.5) / 16.0 - 1.0;
        let y = 1.0 - (j as f32 + 0.5) / 16.0;
        let d = inv.project_point3(Vec3::new(x, y, 1.0)) - inv.project_point3(Vec3::new(x, y, 0.0));
        let want = 2.0 * (d.normalize().x * 0.5 + 0.5);
        assert!((c[0] - want).abs() < 0.05, "({i}, {j}): {c:?} vs {want}");
        assert_eq!(&c[1..], &[0.5, 1.5, 1.0]);
        assert!(!frame.covered(frame.index(i, j)));
        // The reference reads the same map per sub-sample.
        let r = reference.color[reference.index(i, j)];
        assert!((r[0] - c[0]).abs() < 0.05 && r[1] == 0.5, "{r:?} {c:?}");
    }
    // Without `background`, the settings' background colour stays.
    settings.environment = Some(Environment {
        background: false,
        ..env(&m, &s, clip)
    });
    let frame = render(&settings, &[]).unwrap();
    assert_eq!(frame.color[0], [0.0, 0.0, 0.0, 1.0]);
}

#[test]
fn no_seam_pixel_reads_a_coarser_level_than_its_neighbours() {
    // Looking along +z, the seam u = 0 = 1 runs down the middle of the frame.
    let m = maps(map(512, |d| {
        [(d.x * 7.0).sin() as f32 * 0.5 + 0.5, 0.5, 0.5]
    }));
    let s = sampler(4);
    let mut settings = RenderSettings::new(64, 64);
    settings.environment = Some(env(&m, &s, camera(Vec3::Z)));
    settings.capture_footprints = true;
    let frame = render(&settings, &[]).unwrap();
    let lod = |fp: &Footprint| s.lod(&m.radiance, fp);
    let mut crossed = 0;
    for j in 0..64 {
        for i in 0..63 {
            let (a, b) = (
                &frame.footprints[frame.index(i, j)],
                &frame.footprints[frame.index(i + 1, j)],
            );
            if (a.u - b.u).abs() > 0.5 {
                crossed += 1;
                // Differencing u here would give a footprint a whole period wide.
                let naive = Footprint {
                    dudx: b.u - a.u,
                    ..*a
                };
                assert!(lod(&naive) > lod(a) + 4.0);
            }
            assert!(
                (lod(a) - lod(b)).abs() <= 1.0,
                "({i}, {j}): lod {} next to {}",
                lod(a),
                lod(b)
            );
        }
    }
    assert!(crossed >= 60, "the seam is in view: {crossed}");
}

/// A square of side 2 at `z = -3` facing `+z` (towards a camera at the origin), as two
/// triangles with normal `+z`.
fn facing_square() -> Vec<Vertex> {
    [
        (-1.0, -1.0),
        (1.0, -1.0),
        (1.0, 1.0),
        (-1.0, -1.0),
        (1.0, 1.0),
        (-1.0, 1.0),
    ]
    .iter()
    .map(|&(x, y)| {
        let mut v = Vertex::new(Vec3::new(x, y, -3.0), Vec2::ZERO);
        v.normal = Vec3::Z;
        v
    })
    .collect()
}

#[test]
fn a_constant_environment_lights_by_the_split_sum() {
    let l = 0.8f32;
    let m = maps(map(64, |_| [l; 3]));
    let s = sampler(4);
    let white = Texture::from_fn(1, 1, Format::Rgba32Float, &Limits::default(), |_, _| {
        [1.0; 4]
    })
    .unwrap();
    let clip = camera(Vec3::NEG_Z);
    let verts = facing_square();
    let tris = [[0, 1, 2], [3, 4, 5]];
    let shaded = |material: Option<Material>| {
        let mut settings = RenderSettings::new(16, 16);
        settings.environment = Some(env(&m, &s, clip));
        let draw = DrawCall {
            vertices: &verts,
            triangles: &tris,
            texture: &white,
            sampler: &s,
            clip_from_world: clip,
            material,
        };
        let f = render(&settings, &[draw]).unwrap();
        f.color[f.index(8, 8)]
    };
    // Lambertian (no material): c E / pi = c L, times the intensity 2.
    let c = shaded(None);
    assert!((c[0] - 2.0 * l).abs() < 0.02 * l, "{c:?}");
    // A white mirror metal reflects all of it (F0 = 1 and A + B = 1 for a smooth lobe).
    let mirror = Material {
        base_color: Vec4::ONE,
        metallic: 1.0,
        roughness: 0.0,
        ..Material::default()
    };
    let c = shaded(Some(mirror));
    assert!((c[0] - 2.0 * l).abs() < 0.03 * l, "{c:?}");
    // Rough metal loses much to single scattering: head on, the reflectance is the integral
    // of GGX times the height-correlated Smith term, by brute force over the hemisphere.
    let rough = Material {
        roughness: 1.0,
        ..mirror
    };
    let c = shaded(Some(rough));
    let e = white_furnace_head_on(1.0);
    assert!(e > 0.25 && e < 0.4, "{e}");
    assert!(
        (c[0] - 2.0 * l * e as f32).abs() < 0.03 * 2.0 * l,
        "{c:?} vs {e}"
    );
    // A black dielectric shows only its Fresnel reflection, about 4 % head on.
    let black = Material {
        base_color: Vec4::new(0.0, 0.0, 0.0, 1.0),
        roughness: 0.0,
        ..Material::default()
    };
    let c = shaded(Some(black));
    assert!((c[0] - 2.0 * l * 0.04).abs() < 0.01, "{c:?}");
}

/// The directional albedo `E(n.v = 1)` of a white metal of GGX `alpha` (F = 1), integrated on a
/// 400 x 800 grid over the hemisphere of light directions, with the shading model's own `D`
/// and visibility.
fn white_furnace_head_on(alpha: f32) -> f64 {
    use std::f64::consts::PI;
    use texel_raster::material::{ggx_d, smith_visibility};
    let (nt, np) = (400, 800);
    let mut sum = 0.0;
    for i in 0..nt {
        let th = (f64::from(i) + 0.5) / f64::from(nt) * PI / 2.0;
        for j in 0..np {
            let ph = (f64::from(j) + 0.5) / f64::from(np) * 2.0 * PI;
            let l = DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
            let h = (l + DVec3::Z).normalize();
            let f = f64::from(ggx_d(h.z as f32, alpha) * smith_visibility(l.z as f32, 1.0, alpha));
            sum += f * l.z * th.sin() * (PI / 2.0 / f64::from(nt)) * (2.0 * PI / f64::from(np));
        }
    }
    sum
}
