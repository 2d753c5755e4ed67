//! Environment maps: the prefiltered pyramid and irradiance against analytic integrals, the
//! background and the light of a constant environment, and the seam's footprints.

use glam::{DVec3, Mat4, Vec2, Vec3, Vec4};
use texel_raster::environment::{descriptor, roughness_lod, MapLayout, Mapping};
use texel_raster::{
    render, render_reference, DrawCall, Environment, EnvironmentMaps, Material, RenderSettings,
    Vertex,
};
use texel_texture::{Filter, Footprint, Format, Limits, Sampler, SamplerDescriptor, Texture};

const MAPPINGS: [Mapping; 3] = [Mapping::Equirect, Mapping::Cube, Mapping::Octahedral];

/// The float faces of a map of `mapping` holding `f(direction)` at texel centres: a `side x
/// side/2` equirect map, six `side/4`-square cube faces or a `side/2`-square octahedral map
/// (about the same texel angle).
fn faces(mapping: Mapping, side: u32, f: impl Fn(DVec3) -> [f32; 3]) -> Vec<Texture> {
    let (w, h) = match mapping {
        Mapping::Equirect => (side, side / 2),
        Mapping::Cube => (side / 4, side / 4),
        Mapping::Octahedral => (side / 2, side / 2),
    };
    let layout = MapLayout {
        border: 0,
        ..MapLayout::new(mapping, w, h)
    };
    (0..layout.layers())
        .map(|layer| {
            Texture::from_fn(w, h, Format::Rgba32Float, &Limits::default(), |i, j| {
                let c = f(layout.texel_direction(layer, w, h, i, j));
                [c[0], c[1], c[2], 1.0]
            })
            .unwrap()
        })
        .collect()
}

/// [`faces`] prefiltered.
fn maps_of(mapping: Mapping, side: u32, f: impl Fn(DVec3) -> [f32; 3]) -> EnvironmentMaps {
    EnvironmentMaps::new(mapping, faces(mapping, side, f), &Limits::default()).unwrap()
}

/// An equirect map, prefiltered.
fn maps(side: u32, f: impl Fn(DVec3) -> [f32; 3]) -> EnvironmentMaps {
    maps_of(Mapping::Equirect, side, f)
}

fn sampler_for(mapping: Mapping, lab: u8) -> Sampler {
    Sampler::new(descriptor(
        mapping,
        Filter::from_lab_mode(lab)
            .map(SamplerDescriptor::from)
            .unwrap(),
    ))
    .unwrap()
}

fn sampler(lab: u8) -> Sampler {
    sampler_for(Mapping::Equirect, lab)
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

/// The world direction (not normalised) of the ray through the centre of pixel `(i, j)` of an
/// `n x n` frame seen through `clip` (NDC depth 0 to 1, as the renderer casts it).
fn pixel_ray(clip: Mat4, n: u32, i: u32, j: u32) -> DVec3 {
    let inv = clip.inverse();
    let half = n as f32 / 2.0;
    let x = (i as f32 + 0.5) / half - 1.0;
    let y = 1.0 - (j as f32 + 0.5) / half;
    (inv.project_point3(Vec3::new(x, y, 1.0)) - inv.project_point3(Vec3::new(x, y, 0.0))).as_dvec3()
}

#[test]
fn a_constant_map_prefilters_and_integrates_to_itself() {
    for mapping in MAPPINGS {
        let m = maps_of(mapping, 128, |_| [0.5, 1.0, 2.0]);
        // Every level of every layer, border included, is the constant: the radiance and the
        // glossy pyramid (the lobe's weights are normalised).
        for tex in m.radiance.iter().chain(&m.glossy) {
            for (k, l) in tex.levels().iter().enumerate() {
                for (i, j) in [
                    (0, 0),
                    (l.width / 2, l.height / 2),
                    (l.width - 1, l.height - 1),
                ] {
                    let t = tex.texel(k, i, j).unwrap();
                    for (c, want) in t.iter().zip([0.5, 1.0, 2.0]) {
                        assert!(
                            (c - want).abs() < 1e-4 * want,
                            "{mapping:?} level {k} ({i}, {j}): {t:?}"
                        );
                    }
                }
            }
        }
        // E / pi of a constant radiance L is L for every normal (the cosine integrates to pi).
        let l = m.irradiance.levels()[0];
        for j in 0..l.height {
            for i in 0..l.width {
                let e = m.irradiance.texel(0, i, j).unwrap();
                assert!((e[1] - 1.0).abs() < 0.01, "{mapping:?} ({i}, {j}): {e:?}");
            }
        }
    }
}

#[test]
fn irradiance_of_a_bright_upper_hemisphere_follows_the_cosine_law() {
    // L = 1 above the horizon, 0 below: E / pi = (1 + n.y) / 2 exactly, in every mapping.
    for mapping in MAPPINGS {
        let m = maps_of(
            mapping,
            256,
            |d| if d.y > 0.0 { [1.0; 3] } else { [0.0; 3] },
        );
        let s = sampler_for(mapping, 4);
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
                "{mapping:?} {n}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn the_glossy_pyramid_blurs_with_roughness() {
    // A map with one bright band: the prefiltered levels spread it, ever wider.
    let m = maps(256, |d| {
        if d.y.abs() < 0.05 {
            [10.0; 3]
        } else {
            [0.0; 3]
        }
    });
    // Straight up, 60 degrees from the band: dark at level 0 and for a smooth lobe, lit by a
    // rough one.
    let glossy = &m.glossy[0];
    let up = |level: usize| {
        let l = glossy.levels()[level];
        glossy.texel(level, l.width / 2, l.height / 6).unwrap()[0]
    };
    assert_eq!(up(0), 0.0);
    let last = glossy.levels().len() - 1;
    assert!(up(last - 1) > 0.1, "{}", up(last - 1));
    let angle = m.layout.texel_angle();
    assert!(roughness_lod(0.0, angle) < 0.0 && roughness_lod(1.0, angle) > 5.0);
}

#[test]
fn the_background_is_the_map_along_each_camera_ray() {
    for mapping in MAPPINGS {
        let m = maps_of(mapping, 64, |d| [d.x as f32 * 0.5 + 0.5, 0.25, 0.75]);
        let s = sampler_for(mapping, 2);
        let clip = camera(Vec3::new(0.3, 0.2, -1.0));
        let mut settings = RenderSettings::new(32, 32);
        settings.environment = Some(env(&m, &s, clip));
        let frame = render(&settings, &[]).unwrap();
        let reference = render_reference(&settings, &[], 2, 1, None).unwrap();
        for (i, j) in [(0, 0), (16, 16), (31, 5)] {
            let c = frame.color[frame.index(i, j)];
            let d = pixel_ray(clip, 32, i, j);
            let want = 2.0 * (d.normalize().x as f32 * 0.5 + 0.5);
            assert!(
                (c[0] - want).abs() < 0.05,
                "{mapping:?} ({i}, {j}): {c:?} vs {want}"
            );
            assert!(
                (c[1] - 0.5).abs() < 1e-6 && (c[2] - 1.5).abs() < 1e-6,
                "{c:?}"
            );
            assert!(!frame.covered(frame.index(i, j)));
            // The reference reads the same map per sub-sample.
            let r = reference.color[reference.index(i, j)];
            assert!(
                (r[0] - c[0]).abs() < 0.05 && (r[1] - 0.5).abs() < 1e-6,
                "{r:?} {c:?}"
            );
        }
        // Without `background`, the settings' background colour stays.
        settings.environment = Some(Environment {
            background: false,
            ..env(&m, &s, clip)
        });
        let frame = render(&settings, &[]).unwrap();
        assert_eq!(frame.color[0], [0.0, 0.0, 0.0, 1.0]);
    }
}

#[test]
fn no_seam_pixel_reads_a_coarser_level_than_its_neighbours() {
    // Looking along +z, the seam u = 0 = 1 runs down the middle of the frame.
    let m = maps(512, |d| [(d.x * 7.0).sin() as f32 * 0.5 + 0.5, 0.5, 0.5]);
    let s = sampler(4);
    let mut settings = RenderSettings::new(64, 64);
    settings.environment = Some(env(&m, &s, camera(Vec3::Z)));
    settings.capture_footprints = true;
    let frame = render(&settings, &[]).unwrap();
    let lod = |fp: &Footprint| s.lod(&m.radiance[0], fp);
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
    let m = maps(64, |_| [l; 3]);
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
            uv_mapping: None,
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

/// A smooth map: each channel linear in the unit direction.
fn smooth(d: DVec3) -> [f32; 3] {
    let d = d.normalize();
    [
        (0.5 + 0.4 * d.x) as f32,
        (0.5 + 0.4 * d.y) as f32,
        (0.5 + 0.4 * d.z) as f32,
    ]
}

#[test]
fn bordered_cube_faces_continue_onto_their_neighbours_at_every_level() {
    // Every stored texel, border included, holds the map along its own direction (a smooth map
    // barely changes under the box filter): the border is the neighbouring face, not a clamp.
    let m = maps_of(Mapping::Cube, 512, smooth);
    assert_eq!(m.layout.border, m.layout.side / 8);
    let mut worst = 0f32;
    for (layer, tex) in m.radiance.iter().enumerate() {
        for k in 0..4 {
            let l = tex.levels()[k];
            for j in 0..l.height {
                for i in 0..l.width {
                    let d = m.layout.texel_direction(layer, l.width, l.height, i, j);
                    let t = tex.texel(k, i, j).unwrap();
                    for (c, want) in t.iter().zip(smooth(d)) {
                        worst = worst.max((c - want).abs());
                    }
                }
            }
        }
    }
    assert!(worst < 4e-3, "{worst}");
}

#[test]
fn the_octahedral_border_is_the_square_continued_at_every_level() {
    // Past each edge the stored square repeats itself turned about the edge's midpoint (pbrt-v4's
    // wrap), texel for texel, at every level whose border is whole texels.
    let m = maps_of(Mapping::Octahedral, 512, smooth);
    let tex = &m.radiance[0];
    let (n, b) = (m.layout.side, m.layout.border);
    let mut checked = 0;
    for k in 0..4 {
        let (nk, bk) = (n >> k, b >> k);
        for j in 0..nk + 2 * bk {
            for i in 0..nk + 2 * bk {
                let (fi, fj) = (i64::from(i) - i64::from(bk), i64::from(j) - i64::from(bk));
                let inside = |x: i64| (0..i64::from(nk)).contains(&x);
                if inside(fi) && inside(fj) {
                    continue;
                }
                let centre = glam::DVec2::new(fi as f64 + 0.5, fj as f64 + 0.5) / f64::from(nk);
                let w = texel_texture::mapping::sphere::octahedral_wrap(centre) * f64::from(nk);
                let (wi, wj) = (w.x.floor() as u32 + bk, w.y.floor() as u32 + bk);
                let (a, c) = (tex.texel(k, i, j).unwrap(), tex.texel(k, wi, wj).unwrap());
                for (x, y) in a.iter().zip(c) {
                    assert!((x - y).abs() < 1e-6, "level {k} ({i}, {j}) vs ({wi}, {wj})");
                }
                checked += 1;
            }
        }
    }
    assert!(checked > 4 * 256 * 32, "{checked}");
}

#[test]
fn cube_and_octahedral_backgrounds_have_no_seam() {
    // Views of the equirect map near -z (its centre; the seam has its own test) as the baseline,
    // a cube corner (three faces), a cube edge, the octahedral square's outer edge
    // (y = 0 below the horizon) and its corners (-z, where all four meet). Coarse pixels (16
    // across 90 degrees) read levels 3-5 of the map, so every footprint by a face edge reaches
    // past it: read against the smooth map along each ray, and each pixel's level against its
    // neighbours'.
    let views = [
        (Mapping::Equirect, Vec3::new(0.6, 0.05, -1.0)),
        (Mapping::Equirect, Vec3::new(0.05, 0.1, -1.0)),
        (Mapping::Cube, Vec3::new(1.0, 1.0, 1.0)),
        (Mapping::Cube, Vec3::new(1.0, 0.1, -1.0)),
        (Mapping::Octahedral, Vec3::new(0.6, 0.05, -1.0)),
        (Mapping::Octahedral, Vec3::new(0.05, 0.1, -1.0)),
    ];
    for (mapping, forward) in views {
        let m = maps_of(mapping, 1024, smooth);
        for lab in [4, 8] {
            let s = sampler_for(mapping, lab);
            let clip = camera(forward);
            let n = 16;
            let mut settings = RenderSettings::new(n, n);
            settings.environment = Some(Environment {
                intensity: Vec3::ONE,
                ..env(&m, &s, clip)
            });
            settings.capture_footprints = true;
            let frame = render(&settings, &[]).unwrap();
            let mut worst = 0f32;
            let mut layers = std::collections::BTreeSet::new();
            for j in 0..n {
                for i in 0..n {
                    let d = pixel_ray(clip, n, i, j);
                    let want = smooth(d);
                    let c = frame.color[frame.index(i, j)];
                    for k in 0..3 {
                        worst = worst.max((c[k] - want[k]).abs());
                    }
                    layers.insert(m.layout.locate(d).0);
                }
            }
            // The octahedral square creases (it is continuous but bends) along the axis planes
            // and its edges, and a box of texels across a crease averages a bent patch of sky:
            // 0.022 (trilinear) and 0.009 (aniso16) at its edges in these views, where the
            // equirect and cube maps stay within 0.0035. Cube faces with one texel of border
            // (what seamless bilinear filtering fetches) measure 0.019 here.
            let tolerance = if mapping == Mapping::Octahedral {
                0.025
            } else {
                0.005
            };
            assert!(
                worst < tolerance,
                "{mapping:?} {forward} lab {lab}: {worst}"
            );
            if mapping == Mapping::Cube {
                assert!(layers.len() >= 2, "the view crosses faces: {layers:?}");
            }
            // The level: within 1 of every neighbour's.
            let lod = |i: u32, j: u32| {
                let fp = &frame.footprints[frame.index(i, j)];
                let layer = m.layout.locate(pixel_ray(clip, n, i, j)).0;
                s.lod(&m.radiance[layer], fp)
            };
            for j in 0..n {
                for i in 0..n - 1 {
                    let (a, b) = (lod(i, j), lod(i + 1, j));
                    assert!((a - b).abs() <= 1.0, "{mapping:?} ({i}, {j}): {a} {b}");
                    let (a, b) = (lod(j, i), lod(j, i + 1));
                    assert!((a - b).abs() <= 1.0, "{mapping:?} ({j}, {i}): {a} {b}");
                }
            }
        }
    }
}

/// A streamed frame ([`texel_raster::Streaming`]) draws the environment background into every
/// tile, though no triangle reaches any: bit for bit the frame drawn in place. The only test of
/// this binary that sets the process-wide policy: the others may run under either way meanwhile,
/// which changes no image (the property checked here and in `tests/streaming.rs`).
#[test]
fn a_streamed_background_equals_one_drawn_in_place() {
    use texel_raster::{draw_into, set_streaming, ColorTarget, Frame, Streaming};
    let m = maps(64, |d| {
        [d.x as f32 * 0.5 + 0.5, 0.25, d.y as f32 * 0.5 + 0.5]
    });
    let s = sampler(4);
    for target in [ColorTarget::Srgb8, ColorTarget::Float] {
        let mut settings = RenderSettings::new(150, 70);
        settings.target = target;
        settings.environment = Some(env(&m, &s, camera(Vec3::new(0.3, 0.2, -1.0))));
        let draw = |policy| {
            set_streaming(policy);
            let mut frame = Frame::new(&settings);
            assert_eq!(frame.draw_streams(), policy == Streaming::Always);
            draw_into(&settings, &[], &mut frame).unwrap();
            frame
        };
        let (in_place, streamed) = (draw(Streaming::Never), draw(Streaming::Always));
        set_streaming(Streaming::Auto);
        let bits = |f: &Frame| -> Vec<u32> {
            f.color.as_flattened().iter().map(|x| x.to_bits()).collect()
        };
        assert_eq!(bits(&in_place), bits(&streamed), "{target:?}");
        assert_eq!(in_place.color8, streamed.color8, "{target:?}");
        let background = [0.0, 0.0, 0.0, 1.0];
        assert!(in_place.linear().iter().all(|c| *c != background));
    }
}
