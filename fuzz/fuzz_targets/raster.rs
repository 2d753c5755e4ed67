//! The rasterizer: arbitrary triangles and camera (any floats) never panic, and two triangles that
//! share an edge, with their third vertices on opposite sides of it, never both cover a pixel
//! (the top-left fill rule gives each pixel on the shared edge to exactly one of them).
//!
//! The coverage property is checked where it is a property of the geometry rather than of `f64`
//! rounding: world coordinates and camera values within `1e4`, near >= 1e-3, far > near, and every
//! vertex in front of the eye. Beyond that (coordinates near 1e35 were found) clipping itself
//! loses every significant bit, and only "no panic" is required.
#![no_main]

use arbitrary::Arbitrary;
use glam::{Mat4, Vec2, Vec3};
use libfuzzer_sys::fuzz_target;
use texel_raster::{render, DrawCall, RenderSettings, Vertex};
use texel_texture::{
    AddressMode, FilterMode, Limits, MipmapFilterMode, Sampler, SamplerDescriptor, Texture,
};

#[derive(Arbitrary, Debug)]
struct Input {
    width: u8,
    height: u8,
    positions: [[f32; 3]; 4],
    uvs: [[f32; 2]; 4],
    eye: [f32; 3],
    target: [f32; 3],
    fovy_deg: f32,
    near: f32,
    far: f32,
}

/// Screen position (pixels) of a world point and its clip w.
fn project(m: Mat4, p: Vec3, w: f32, h: f32) -> (Vec2, f32) {
    let c = m * p.extend(1.0);
    let ndc = Vec2::new(c.x / c.w, c.y / c.w);
    (
        Vec2::new((ndc.x + 1.0) * 0.5 * w, (1.0 - ndc.y) * 0.5 * h),
        c.w,
    )
}

fuzz_target!(|input: Input| {
    let (w, h) = (
        u32::from(input.width % 32) + 1,
        u32::from(input.height % 32) + 1,
    );
    let tex = Texture::from_fn(
        8,
        8,
        texel_texture::Format::Rgba8Unorm,
        &Limits::default(),
        |i, j| {
            let v = ((i + j) % 2) as f32;
            [v, v, v, 1.0]
        },
    )
    .unwrap();
    let sampler = Sampler::new(SamplerDescriptor {
        mag_filter: FilterMode::Linear,
        min_filter: FilterMode::Linear,
        mipmap_filter: MipmapFilterMode::Linear,
        ..SamplerDescriptor::default().with_address_mode(AddressMode::Repeat)
    })
    .unwrap();
    let clip_from_world =
        Mat4::perspective_rh_gl(
            input.fovy_deg.to_radians(),
            w as f32 / h as f32,
            input.near,
            input.far,
        ) * Mat4::look_at_rh(Vec3::from(input.eye), Vec3::from(input.target), Vec3::Y);
    let vertices: Vec<Vertex> = (0..4)
        .map(|k| Vertex::new(Vec3::from(input.positions[k]), Vec2::from(input.uvs[k])))
        .collect();
    // One rayon pool for the whole run (scripts/fuzz.sh sets RAYON_NUM_THREADS=1), not one per frame.
    let settings = RenderSettings::new(w, h);
    let draw = |triangles: &[[u32; 3]]| {
        let call = DrawCall {
            vertices: &vertices,
            triangles,
            texture: &tex,
            sampler: &sampler,
            clip_from_world,
            material: None,
            uv_mapping: None,
        };
        render(&settings, &[call]).expect("valid draw").coverage()
    };
    let first = [[0u32, 1, 2]];
    let second = [[1u32, 0, 3]];
    let c1 = draw(&first);
    let c2 = draw(&second);
    let _ = draw(&[first[0], second[0]]);
    // Disjoint interiors: every vertex in front of the eye (a perspective map then keeps sides of
    // lines) and the third vertices clearly on opposite sides of the shared edge in screen space.
    let p: Vec<(Vec2, f32)> = input
        .positions
        .iter()
        .map(|&q| project(clip_from_world, Vec3::from(q), w as f32, h as f32))
        .collect();
    let sane = |v: &[f32]| v.iter().all(|x| x.abs() <= 1e4);
    let in_domain = input.positions.iter().all(|q| sane(q))
        && sane(&input.eye)
        && sane(&input.target)
        && input.fovy_deg > 1.0
        && input.fovy_deg < 179.0
        && input.near >= 1e-3
        && input.far > input.near
        && input.far <= 1e4;
    if !in_domain
        || !p
            .iter()
            .all(|(s, cw)| *cw > 1e-3 && s.is_finite() && s.abs().max_element() < 1e6)
    {
        return;
    }
    let edge = p[1].0 - p[0].0;
    let len = edge.length();
    if !(len > 1e-3) {
        return;
    }
    let side = |q: Vec2| edge.perp_dot(q - p[0].0) / len; // signed distance in pixels
    let (s2, s3) = (side(p[2].0), side(p[3].0));
    if s2 * s3 < 0.0 && s2.abs() > 0.05 && s3.abs() > 0.05 {
        for (k, (a, b)) in c1.iter().zip(&c2).enumerate() {
            assert!(
                !(*a && *b),
                "pixel {k} covered by both triangles: {input:?}"
            );
        }
    }
});
