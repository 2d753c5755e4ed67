//! A scene made ready to draw: textures decoded and their pyramids built once, meshes turned into the
//! rasterizer's vertices, the camera into `clip_from_world`, and one sampler per mesh for a filter.

use std::collections::BTreeMap;

use anyhow::{Context, Result};
use texel_raster::{DrawCall, RenderSettings, Vertex};
use texel_scene::{Scene, SceneLimits};
use texel_texture::color::srgb_to_linear;
use texel_texture::{ColorSpace, Limits, Sampler, Texture, TextureError};

use crate::budget::{Budget, FRAME_BYTES_PER_PIXEL};
use crate::cli::{ColorArg, Size};
use crate::filters::FilterName;

/// What a scene keeps per vertex, at most: the scene's position, uv, normal and colour (48 bytes)
/// and the rasterizer's [`Vertex`].
const VERTEX_BYTES: u64 = 48 + std::mem::size_of::<Vertex>() as u64;

/// What a scene keeps per triangle: its indices (12 bytes) and an allowance of 244 bytes for the
/// rasterizer's per-frame triangle set-up and bins.
const TRIANGLE_BYTES: u64 = 256;

/// How a command reads its inputs: the memory account and the non-finite-texel policy.
pub struct Input {
    /// The `--max-memory` account.
    pub budget: Budget,
    /// `--sanitize`: replace NaN/Inf texels instead of refusing them.
    pub sanitize: bool,
}

impl Input {
    /// Print a warning when `--sanitize` replaced values of texture `name`.
    pub fn warn_replaced(&self, name: &str, replaced: u64) {
        if replaced > 0 {
            eprintln!(
                "texel: warning: texture {name:?}: replaced {replaced} NaN or infinite channel values (NaN -> 0, +-inf -> +-{})",
                texel_texture::NON_FINITE_CLAMP
            );
        }
    }

    /// Add to a texture's memory-limit error which flag sets the limit.
    pub fn explain(&self, e: anyhow::Error) -> anyhow::Error {
        let over = e.chain().any(|c| {
            matches!(
                c.downcast_ref::<TextureError>(),
                Some(
                    TextureError::OverMemoryLimit { .. }
                        | TextureError::StructureOverMemoryLimit { .. }
                )
            )
        });
        if over {
            e.context(format!(
                "the memory limit is what remains of {} after the other inputs",
                self.budget.describe()
            ))
        } else {
            e
        }
    }
}

/// A loaded scene, ready to render with any filter.
pub struct Prepared {
    /// The scene as loaded.
    pub scene: Scene,
    /// Every texture by name, with its pyramid.
    pub textures: BTreeMap<String, Texture>,
    /// Each mesh's vertices.
    pub vertices: Vec<Vec<Vertex>>,
    /// Output size.
    pub width: u32,
    /// Output size.
    pub height: u32,
    /// The colour handling the textures were loaded with.
    pub color: ColorArg,
}

impl Prepared {
    /// Load `scene` (a path or `builtin:NAME`) and its textures, accounting for the meshes, every
    /// texture and one frame of the output size in `input.budget` before each is allocated.
    pub fn load(
        scene: &str,
        color: ColorArg,
        size: Option<Size>,
        input: &mut Input,
    ) -> Result<Self> {
        let scene = Scene::load_with(scene, &SceneLimits::default())
            .with_context(|| format!("cannot load scene {scene}"))?;
        let override_space = match color {
            ColorArg::Srgb => None,
            ColorArg::Raw => Some(ColorSpace::Linear),
        };
        let (width, height) = size.map_or((scene.output.width, scene.output.height), |s| {
            (s.width, s.height)
        });
        let (verts, tris) = scene.meshes.iter().fold((0u64, 0u64), |(v, t), m| {
            (v + m.positions.len() as u64, t + m.triangles.len() as u64)
        });
        input
            .budget
            .take("the meshes", verts * VERTEX_BYTES + tris * TRIANGLE_BYTES)?;
        input.budget.take(
            &format!("a {width}x{height} frame"),
            u64::from(width) * u64::from(height) * FRAME_BYTES_PER_PIXEL,
        )?;
        let mut textures = BTreeMap::new();
        for m in &scene.meshes {
            if textures.contains_key(&m.texture) {
                continue;
            }
            let spec = &scene.textures[&m.texture];
            let limits = Limits {
                max_bytes: input.budget.remaining(),
                ..Limits::default()
            };
            let loaded = spec
                .load_with(&m.texture, override_space, &limits, input.sanitize)
                .map_err(|e| input.explain(e.into()))?;
            input.warn_replaced(&m.texture, loaded.replaced);
            input.budget.take(
                &format!("texture {:?}", m.texture),
                loaded.texture.pyramid_bytes(),
            )?;
            textures.insert(m.texture.clone(), loaded.texture);
        }
        let vertices = scene.meshes.iter().map(texel_vertices).collect();
        Ok(Prepared {
            scene,
            textures,
            vertices,
            width,
            height,
            color,
        })
    }

    /// One sampler per mesh for `filter`, with each mesh's address modes.
    pub fn samplers(&self, filter: FilterName) -> Result<Vec<Sampler>> {
        self.scene
            .meshes
            .iter()
            .map(|m| {
                let desc = filter.descriptor(m.address_mode_u, m.address_mode_v)?;
                Sampler::new(desc)
                    .with_context(|| format!("invalid sampler for filter {}", filter.name()))
            })
            .collect()
    }

    /// One sampler per mesh when the user names no filter: a glTF mesh's own sampler filters
    /// (`magFilter`/`minFilter`; what the glTF leaves unspecified is linear, as for trilinear),
    /// and trilinear for every other mesh.
    pub fn default_samplers(&self) -> Result<Vec<Sampler>> {
        self.scene
            .meshes
            .iter()
            .map(|m| {
                let mut desc =
                    FilterName::Trilinear.descriptor(m.address_mode_u, m.address_mode_v)?;
                if let Some(f) = &m.filters {
                    desc.mag_filter = f.mag_filter.unwrap_or(desc.mag_filter);
                    desc.min_filter = f.min_filter.unwrap_or(desc.min_filter);
                    desc.mipmap_filter = f.mipmap_filter.unwrap_or(desc.mipmap_filter);
                }
                Sampler::new(desc).context("invalid sampler from the glTF file")
            })
            .collect()
    }

    /// Build the acceleration structures `samplers` need (ripmaps, summed-area tables) ahead of
    /// timing, and return the bytes of every structure the frame uses (pyramids included), counting
    /// each texture once.
    pub fn prepare(&self, samplers: &[Sampler]) -> Result<u64> {
        let mut bytes = BTreeMap::new();
        for (mesh, sampler) in self.scene.meshes.iter().zip(samplers) {
            let tex = &self.textures[&mesh.texture];
            tex.prepare(sampler)
                .with_context(|| format!("cannot prepare texture {:?}", mesh.texture))?;
            let b = tex.structure_bytes(sampler.descriptor());
            let e = bytes.entry(mesh.texture.clone()).or_insert(0u64);
            *e = (*e).max(b);
        }
        Ok(bytes.values().sum())
    }

    /// The draw calls of the whole scene with `samplers` (one per mesh).
    pub fn draws<'a>(&'a self, samplers: &'a [Sampler]) -> Vec<DrawCall<'a>> {
        let aspect = self.width as f32 / self.height as f32;
        let clip_from_world = self.scene.camera.clip_from_world(aspect);
        self.scene
            .meshes
            .iter()
            .zip(&self.vertices)
            .zip(samplers)
            .map(|((mesh, vertices), sampler)| DrawCall {
                vertices,
                triangles: &mesh.triangles,
                texture: &self.textures[&mesh.texture],
                sampler,
                clip_from_world,
            })
            .collect()
    }

    /// Render settings for this scene's size and background.
    pub fn settings(&self) -> RenderSettings {
        let mut s = RenderSettings::new(self.width, self.height);
        let bg = self.scene.output.background;
        let decode = |b: u8| match self.color {
            ColorArg::Srgb => srgb_to_linear(f32::from(b) / 255.0),
            ColorArg::Raw => f32::from(b) / 255.0,
        };
        s.background = [
            decode(bg[0]),
            decode(bg[1]),
            decode(bg[2]),
            f32::from(bg[3]) / 255.0,
        ];
        s
    }
}

fn texel_vertices(mesh: &texel_scene::Mesh) -> Vec<Vertex> {
    (0..mesh.positions.len())
        .map(|k| {
            let mut v = Vertex::new(mesh.positions[k], mesh.uvs[k]);
            if let Some(c) = &mesh.colors {
                v.color = c[k];
            }
            if let Some(n) = &mesh.normals {
                v.normal = n[k];
            }
            v
        })
        .collect()
}
