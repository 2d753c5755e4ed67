//! A scene made ready to draw: textures decoded and their pyramids built once, meshes turned into the
//! rasterizer's vertices, the camera into `clip_from_world`, and one sampler per mesh for a filter.

use std::collections::BTreeMap;

use anyhow::{Context, Result};
use texel_raster::{DrawCall, RenderSettings, Vertex};
use texel_scene::Scene;
use texel_texture::color::srgb_to_linear;
use texel_texture::{ColorSpace, Limits, Sampler, Texture};

use crate::cli::{ColorArg, Size};
use crate::filters::FilterName;

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
    /// Load `scene` (a path or `builtin:NAME`) and its textures.
    pub fn load(scene: &str, color: ColorArg, size: Option<Size>) -> Result<Self> {
        let scene = Scene::load(scene).with_context(|| format!("cannot load scene {scene}"))?;
        let override_space = match color {
            ColorArg::Srgb => None,
            ColorArg::Raw => Some(ColorSpace::Linear),
        };
        let textures = scene.load_textures(override_space, &Limits::default())?;
        let vertices = scene.meshes.iter().map(texel_vertices).collect();
        let (width, height) = size.map_or((scene.output.width, scene.output.height), |s| (s.width, s.height));
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
                Sampler::new(desc).with_context(|| format!("invalid sampler for filter {}", filter.name()))
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
            tex.prepare(sampler).with_context(|| format!("cannot prepare texture {:?}", mesh.texture))?;
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
        s.background = [decode(bg[0]), decode(bg[1]), decode(bg[2]), f32::from(bg[3]) / 255.0];
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
