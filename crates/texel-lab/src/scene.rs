//! A texel scene as the lab sees it: prepared with raw colour (texture bytes read as they are,
//! as a plain `RGBA8` texture on the device), its draws turned into what the device uploads.

use std::path::Path;

use texel_prepare::{ColorHandling, MemoryBudget, PreparedScene, SceneOptions};
use texel_raster::{DrawCall, UvEvaluation};
use texel_texture::{Filter, LevelTexels, Sampler};

use crate::gl::{GlDraw, GlScene};
use crate::Error;

/// The lab's own scenes, shipped under `scenes/lab/` and built into the library.
pub const LAB_SCENES: [(&str, &str); 3] = [
    (
        "lab-tunnel",
        include_str!("../../../scenes/lab/tunnel.toml"),
    ),
    ("lab-plane", include_str!("../../../scenes/lab/plane.toml")),
    ("lab-wall", include_str!("../../../scenes/lab/wall.toml")),
];

/// A prepared scene and the samplers whose textures and address modes its draws use.
pub struct LabScene {
    /// The scene's name in reports.
    pub name: String,
    /// The scene, prepared with raw colour.
    pub prepared: PreparedScene,
    samplers: Vec<Sampler>,
}

impl LabScene {
    /// Load `spec` (a lab scene's name, a built-in scene's name or a scene file) at `size`.
    ///
    /// # Errors
    /// [`Error::Scene`] for a scene that cannot be loaded; [`Error::Unsupported`] for a lit
    /// scene (a material) or a per-pixel sphere mapping: the lab's shaders read an unlit
    /// texture through the interpolated coordinate.
    pub fn load(spec: &str, size: Option<(u32, u32)>) -> Result<LabScene, Error> {
        let scene = match LAB_SCENES.iter().find(|(n, _)| *n == spec) {
            Some((_, text)) => texel_scene::Scene::from_toml_str(text, Path::new("scenes/lab"))
                .map_err(|e| Error::Scene(format!("{spec}: {e}")))?,
            None => texel_scene::Scene::load(spec).map_err(|e| Error::Scene(e.to_string()))?,
        };
        let options = SceneOptions {
            size,
            color: ColorHandling::Raw,
            surface_uv: UvEvaluation::PerVertex,
            ..SceneOptions::default()
        };
        let mut budget = MemoryBudget::process_default();
        let prepared = PreparedScene::new(scene, &options, &mut budget)
            .map_err(|e| Error::Scene(e.to_string()))?;
        let samplers = prepared
            .samplers(Filter::Bilinear)
            .map_err(|e| Error::Scene(e.to_string()))?;
        let name = Path::new(spec)
            .file_stem()
            .map_or(spec.to_string(), |s| s.to_string_lossy().into_owned());
        let lab = LabScene {
            name,
            prepared,
            samplers,
        };
        for d in lab.draws() {
            if d.material.is_some() {
                return Err(Error::Unsupported(format!(
                    "{spec} has lit materials; the lab's shaders read an unlit texture"
                )));
            }
        }
        Ok(lab)
    }

    /// The scene's draws (bilinear samplers: only their textures and address modes matter).
    pub fn draws(&self) -> Vec<DrawCall<'_>> {
        self.prepared.draws(&self.samplers)
    }

    /// Frame size.
    pub fn size(&self) -> (u32, u32) {
        (self.prepared.width, self.prepared.height)
    }

    /// What the device uploads.
    pub fn device_scene(&self) -> GlScene {
        let draws = self.draws();
        let settings = self
            .prepared
            .settings_for(&self.samplers, &self.prepared.scene.camera);
        let bg = settings
            .background
            .map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
        let clip_from_world = draws
            .first()
            .map_or(glam::Mat4::IDENTITY, |d| d.clip_from_world)
            .to_cols_array();
        device_scene(
            &draws,
            (self.prepared.width, self.prepared.height),
            bg,
            clip_from_world,
        )
    }
}

/// What the device uploads for `draws` seen through `clip_from_world` at `size`: each texture's
/// levels as the 8-bit codes texel stores (a texture decoded to float is encoded back in its
/// source's colour space, so the codes are the file's).
pub fn device_scene(
    draws: &[DrawCall],
    (width, height): (u32, u32),
    background: [u8; 4],
    clip_from_world: [f32; 16],
) -> GlScene {
    GlScene {
        width,
        height,
        background,
        clip_from_world,
        draws: draws.iter().map(device_draw).collect(),
    }
}

fn device_draw(d: &DrawCall) -> GlDraw {
    let t = d.texture;
    let srgb = t.source_format() == texel_texture::Format::Rgba8Srgb;
    let levels = (0..t.levels().len())
        .filter_map(|k| {
            let info = &t.levels()[k];
            let texels = match t.level_texels(k)? {
                LevelTexels::Unorm8(c) => c.to_vec(),
                LevelTexels::Float(f) if srgb => f
                    .iter()
                    .map(|&p| texel_texture::base::color::rgba_to_srgb8(p))
                    .collect(),
                LevelTexels::Float(f) => f
                    .iter()
                    .map(|p| p.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8))
                    .collect(),
            };
            Some((info.width, info.height, texels))
        })
        .collect();
    GlDraw {
        positions: d.vertices.iter().map(|v| v.position.to_array()).collect(),
        uvs: d.vertices.iter().map(|v| v.uv.to_array()).collect(),
        indices: d.triangles.iter().flatten().copied().collect(),
        levels,
    }
}
