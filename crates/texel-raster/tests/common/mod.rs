//! Shared test scenes: the ground plane of `scenes/ground.toml`, built inline.
#![allow(dead_code, unused_imports)]

use glam::{DMat4, DVec2, DVec4, Mat4, Vec2, Vec3};
use texel_raster::{camera, DrawCall, Vertex};
use texel_texture::{
    AddressMode, ColorSpace, Filter, Format, Limits, Sampler, SamplerDescriptor, Texture,
};

/// The ground scene's camera.
pub(crate) const EYE: Vec3 = Vec3::new(0.0, 1.0, 0.0);
pub(crate) const TARGET: Vec3 = Vec3::new(0.0, 0.75, -10.0);

/// A `size x size` checker of `checks x checks` squares; texel (0, 0) lies in a black check. sRGB.
pub(crate) fn checker(size: u32, checks: u32) -> Texture {
    let cell = size / checks;
    let texels = (0..size * size)
        .map(|k| {
            let (i, j) = (k % size, k / size);
            if (i / cell + j / cell).is_multiple_of(2) {
                [0, 0, 0, 255]
            } else {
                [255, 255, 255, 255]
            }
        })
        .collect();
    Texture::from_rgba8(size, size, texels, ColorSpace::Srgb, &Limits::default()).unwrap()
}

/// A Repeat sampler from a lab mode (1 nearest, 2 bilinear, 3 mip nearest, 4 trilinear).
pub(crate) fn lab_sampler(mode: u8) -> Sampler {
    Sampler::new(
        Filter::from_lab_mode(mode)
            .map(SamplerDescriptor::from)
            .unwrap()
            .with_address_mode(AddressMode::Repeat),
    )
    .unwrap()
}

/// The ground scene's geometry and camera for a `width x height` frame.
pub(crate) struct Ground {
    pub vertices: Vec<Vertex>,
    pub triangles: Vec<[u32; 3]>,
    pub texture: Texture,
    pub clip_from_world: Mat4,
}

impl Ground {
    pub(crate) fn new(width: u32, height: u32) -> Self {
        Self::with_texture(width, height, checker(1024, 8))
    }

    pub(crate) fn with_texture(width: u32, height: u32, texture: Texture) -> Self {
        let positions = [
            [-500.0, 0.0, 1.0],
            [500.0, 0.0, 1.0],
            [500.0, 0.0, -1000.0],
            [-500.0, 0.0, -1000.0],
        ];
        let uvs = [
            [-250.0, -0.5],
            [250.0, -0.5],
            [250.0, 500.0],
            [-250.0, 500.0],
        ];
        let vertices = positions
            .iter()
            .zip(uvs)
            .map(|(p, uv)| Vertex::new(Vec3::from_array(*p), Vec2::from_array(uv)))
            .collect();
        let proj = camera::perspective(
            50f32.to_radians(),
            width as f32 / height as f32,
            0.05,
            2000.0,
        );
        Ground {
            vertices,
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            texture,
            clip_from_world: proj * camera::look_at(EYE, TARGET, Vec3::Y),
        }
    }

    pub(crate) fn draw<'a>(&'a self, sampler: &'a Sampler) -> DrawCall<'a> {
        DrawCall {
            vertices: &self.vertices,
            triangles: &self.triangles,
            texture: &self.texture,
            sampler,
            clip_from_world: self.clip_from_world,
            material: None,
            uv_mapping: None,
        }
    }

    /// The exact uv where the ray through pixel coordinates `(x, y)` meets the ground plane `y = 0`
    /// (`u = X / 2`, `v = -Z / 2` from the scene's positions and uvs), or `None` above the horizon.
    pub(crate) fn analytic_uv(&self, x: f64, y: f64, width: u32, height: u32) -> Option<DVec2> {
        let world_from_clip: DMat4 = self.clip_from_world.as_dmat4().inverse();
        let x_ndc = 2.0 * x / f64::from(width) - 1.0;
        let y_ndc = 1.0 - 2.0 * y / f64::from(height);
        let far = world_from_clip * DVec4::new(x_ndc, y_ndc, 1.0, 1.0);
        let far = far.truncate() / far.w;
        let eye = EYE.as_dvec3();
        let dir = far - eye;
        if dir.y >= 0.0 {
            return None;
        }
        let t = -eye.y / dir.y;
        let p = eye + dir * t;
        Some(DVec2::new(p.x / 2.0, -p.z / 2.0))
    }
}

/// The project's deterministic generator (SplitMix64), for test geometry.
pub(crate) use texel_texture::base::rng::SplitMix64 as Rng;

/// A vertex given in pixel coordinates of a `width x height` frame, for `clip_from_world = I`.
pub(crate) fn screen_vertex(x: f64, y: f64, width: u32, height: u32) -> Vertex {
    let xn = 2.0 * x / f64::from(width) - 1.0;
    let yn = 1.0 - 2.0 * y / f64::from(height);
    Vertex::new(
        Vec3::new(xn as f32, yn as f32, 0.0),
        Vec2::new(
            (x / f64::from(width)) as f32,
            (y / f64::from(height)) as f32,
        ),
    )
}

/// A 1x1 white texture and a nearest sampler.
pub(crate) fn white() -> (Texture, Sampler) {
    (
        Texture::from_fn(
            1,
            1,
            texel_texture::Format::Rgba8Unorm,
            &Limits::default(),
            |_, _| [1.0; 4],
        )
        .unwrap(),
        Sampler::new(SamplerDescriptor::default()).unwrap(),
    )
}

/// The benchmarks' mesh: an `nx x ny` grid of cells over a `w x h` frame, two triangles per cell
/// (224 x 224 cells give 100 352 triangles of about 9 pixels each at 1280 x 720), and a 64 x 64
/// gradient texture to map on it with an identity `clip_from_world`.
pub(crate) fn screen_grid(
    w: u32,
    h: u32,
    nx: u32,
    ny: u32,
) -> (Vec<Vertex>, Vec<[u32; 3]>, Texture) {
    let vertices = (0..=ny)
        .flat_map(|b| {
            (0..=nx).map(move |a| {
                screen_vertex(
                    f64::from(a) * f64::from(w) / f64::from(nx),
                    f64::from(b) * f64::from(h) / f64::from(ny),
                    w,
                    h,
                )
            })
        })
        .collect();
    let triangles = (0..ny)
        .flat_map(|b| {
            (0..nx).flat_map(move |a| {
                let k = b * (nx + 1) + a;
                [[k, k + 1, k + nx + 2], [k, k + nx + 2, k + nx + 1]]
            })
        })
        .collect();
    let texture = Texture::from_fn(64, 64, Format::Rgba8Srgb, &Limits::default(), |i, j| {
        [i as f32 / 63.0, j as f32 / 63.0, 0.5, 1.0]
    })
    .expect("64x64 texture");
    (vertices, triangles, texture)
}
