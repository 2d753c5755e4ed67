//! Lighting with materials: a normal-mapped plane against the shading model evaluated by hand.

mod lit_plane;

use glam::{Mat4, Vec3};
use lit_plane::{plane, view, H, PLANE_TRIANGLES, W};
use texel_raster::material::{radiance, Surface};
use texel_raster::{render, DrawCall, Light, Material, RenderSettings, TextureInput, MAX_LIGHTS};
use texel_texture::{Format, Limits, Sampler, SamplerDescriptor, Texture};

/// A 1x1 RGBA8 (linear) texture of grey level `v` (stored as its 8-bit code).
fn grey(v: f32) -> Texture {
    Texture::from_fn(1, 1, Format::Rgba8Unorm, &Limits::default(), |_, _| [v; 4]).unwrap()
}

/// Where the ray through pixel `(i, j)`'s centre meets z = 0.
fn hit(m: Mat4, eye: Vec3, i: u32, j: u32) -> Vec3 {
    let x = (i as f32 + 0.5) / W as f32 * 2.0 - 1.0;
    let y = 1.0 - (j as f32 + 0.5) / H as f32 * 2.0;
    let far = m.inverse().project_point3(Vec3::new(x, y, 1.0));
    let d = far - eye;
    eye + d * (-eye.z / d.z)
}

#[test]
fn a_normal_map_tilts_the_shading_normal_in_gltf_tangent_space() {
    // Every texel holds the tangent-space normal (0.3, 0.4, 1) normalised, as 8-bit codes.
    let n_t = Vec3::new(0.3, 0.4, 1.0).normalize();
    let code = |c: f32| ((c + 1.0) / 2.0 * 255.0).round() as u8;
    let texel = [code(n_t.x), code(n_t.y), code(n_t.z), 255];
    let decoded = Vec3::new(
        f32::from(texel[0]),
        f32::from(texel[1]),
        f32::from(texel[2]),
    ) / 255.0
        * 2.0
        - Vec3::ONE;
    let normals = Texture::from_rgba8(
        4,
        4,
        vec![texel; 16],
        texel_texture::ColorSpace::Linear,
        &Limits::default(),
    )
    .unwrap();
    let white = grey(1.0);
    let sampler = Sampler::new(SamplerDescriptor::default()).unwrap();
    let vertices = plane();
    let (m, eye) = view();
    let light = Light::Directional {
        direction: Vec3::new(-0.5, 0.2, 1.0),
        intensity: Vec3::splat(3.0),
    };
    let mut lights = [None; MAX_LIGHTS];
    lights[0] = Some(light);
    let settings = RenderSettings {
        lights,
        ..RenderSettings::new(W, H)
    };
    for (scale, roughness) in [(1.0f32, 0.6f32), (0.0, 0.3), (0.5, 1.0)] {
        let material = Material {
            roughness,
            normal_map: Some(TextureInput {
                texture: &normals,
                sampler: &sampler,
            }),
            normal_scale: scale,
            ..Material::default()
        };
        let draw = DrawCall {
            vertices: &vertices,
            triangles: &PLANE_TRIANGLES,
            texture: &white,
            sampler: &sampler,
            clip_from_world: m,
            material: Some(material),
            uv_mapping: None,
        };
        let frame = render(&settings, &[draw]).unwrap();
        // Tangent +x, bitangent +y, normal +z: the world normal is the scaled map normal.
        let world = (decoded * Vec3::new(scale, scale, 1.0)).normalize();
        for (i, j) in [(48, 32), (30, 20), (70, 45), (40, 50)] {
            let k = frame.index(i, j);
            assert!(frame.covered(k), "({i}, {j}) not covered");
            let surface = Surface {
                base: Vec3::ONE,
                roughness,
                metallic: 0.0,
                normal: world,
                diffuse_normal: world,
                position: hit(m, eye, i, j),
                occlusion: 1.0,
                spread: None,
            };
            let want = radiance(&surface, eye, &[light], false);
            let got = Vec3::from_slice(&frame.color[k][..3]);
            assert!(
                (got - want).abs().max_element() < 2e-4 * want.max_element().max(1.0),
                "scale {scale}, ({i}, {j}): got {got}, want {want}"
            );
        }
    }
}

#[test]
fn lights_without_a_material_are_lambertian_and_unlit_frames_ignore_normals() {
    let white = grey(0.5);
    let sampler = Sampler::new(SamplerDescriptor::default()).unwrap();
    let vertices = plane();
    let (m, eye) = view();
    let draw = DrawCall {
        vertices: &vertices,
        triangles: &PLANE_TRIANGLES,
        texture: &white,
        sampler: &sampler,
        clip_from_world: m,
        material: None,
        uv_mapping: None,
    };
    // 0.5 stored as the 8-bit code 128.
    let c = white.texel(0, 0, 0).unwrap()[0];
    let unlit = render(&RenderSettings::new(W, H), &[draw]).unwrap();
    assert_eq!(unlit.color[unlit.index(48, 32)], [c; 4]);
    let mut lights = [None; MAX_LIGHTS];
    // A point light 2 units in front of the plane's centre, and ambient light.
    lights[2] = Some(Light::Point {
        position: Vec3::new(0.0, 0.0, 2.0),
        intensity: Vec3::splat(8.0),
    });
    lights[5] = Some(Light::Ambient {
        intensity: Vec3::splat(0.2),
    });
    let lit = render(
        &RenderSettings {
            lights,
            ..RenderSettings::new(W, H)
        },
        &[draw],
    )
    .unwrap();
    for (i, j) in [(48, 32), (36, 22)] {
        assert!(lit.covered(lit.index(i, j)));
        let p = hit(m, eye, i, j);
        let d = Vec3::new(0.0, 0.0, 2.0) - p;
        let cos = d.normalize().z;
        let want = c / std::f32::consts::PI * 8.0 / d.length_squared() * cos + 0.2 * c;
        let got = lit.color[lit.index(i, j)][0];
        assert!((got - want).abs() < 1e-4, "({i}, {j}): {got} vs {want}");
    }
}
