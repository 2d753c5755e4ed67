//! From a [`TextureSpec`] to a sampled [`Texture`].

use std::collections::BTreeMap;

use texel_texture::{ColorSpace, Limits, LoadOptions, Loaded, Texture};

use crate::error::SceneError;
use crate::model::{Scene, TextureSource, TextureSpec};

impl TextureSpec {
    /// The colour space used: `color_override` (the CLI's `--color raw` passes
    /// `Some(ColorSpace::Linear)`) or the spec's own.
    pub fn color_space(&self, color_override: Option<ColorSpace>) -> ColorSpace {
        color_override.unwrap_or(self.color)
    }

    /// Load or generate the texture (with its mip pyramid). `name` is used in error messages.
    ///
    /// # Errors
    /// [`SceneError::Texture`] carrying the name (and the path for files): missing or unreadable
    /// file, corrupt image, size or memory over `limits`.
    pub fn load(
        &self,
        name: &str,
        color_override: Option<ColorSpace>,
        limits: &Limits,
    ) -> Result<Texture, SceneError> {
        self.load_with(name, color_override, limits, false)
            .map(|l| l.texture)
    }

    /// As [`TextureSpec::load`]; with `replace_non_finite`, NaN, infinite and out-of-range float texels are
    /// replaced ([`texel_texture::replace_non_finite`]) rather than refused, and counted.
    ///
    /// # Errors
    /// As [`TextureSpec::load`].
    pub fn load_with(
        &self,
        name: &str,
        color_override: Option<ColorSpace>,
        limits: &Limits,
        replace_non_finite: bool,
    ) -> Result<Loaded, SceneError> {
        let color = self.color_space(color_override);
        match &self.source {
            TextureSource::File(path) => {
                let options = LoadOptions {
                    replace_non_finite,
                    ..LoadOptions::new(color, *limits)
                };
                Texture::load_with(path, &options).map_err(|source| SceneError::Texture {
                    name: name.to_string(),
                    path: Some(path.clone()),
                    source,
                })
            }
            TextureSource::Encoded(e) => {
                let options = LoadOptions {
                    replace_non_finite,
                    ..LoadOptions::new(color, *limits)
                };
                Texture::decode_with(&e.bytes, &options).map_err(|source| SceneError::Texture {
                    name: format!("{name} ({})", e.origin),
                    path: None,
                    source,
                })
            }
            TextureSource::Procedural(p) => p
                .generate(color, limits)
                .map(|texture| Loaded {
                    texture,
                    replaced: 0,
                })
                .map_err(|source| SceneError::Texture {
                    name: name.to_string(),
                    path: None,
                    source,
                }),
        }
    }
}

/// One texture a scene draws with ([`Scene::used_textures`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TextureUse<'a> {
    /// The first mesh that uses it.
    pub mesh: usize,
    /// Its name in [`Scene::textures`].
    pub name: &'a str,
    /// Whether it holds colour (a mesh's base colour texture), which a colour-space override
    /// such as the CLI's `--color raw` applies to; material maps (normals, roughness,
    /// metalness) hold data and keep their own colour space.
    pub color: bool,
}

impl Scene {
    /// Every texture the meshes and their materials use, once each, in first-use order: each
    /// mesh's colour texture, then its material's maps.
    pub fn used_textures(&self) -> Vec<TextureUse<'_>> {
        let mut out: Vec<TextureUse> = Vec::new();
        for (mesh, m) in self.meshes.iter().enumerate() {
            let maps = m
                .material
                .as_ref()
                .and_then(|n| self.materials.get(n))
                .map(|mat| mat.texture_uses())
                .unwrap_or_default();
            let uses = std::iter::once((m.texture.as_str(), true)).chain(maps);
            for (name, color) in uses {
                if !out.iter().any(|u| u.name == name) {
                    out.push(TextureUse { mesh, name, color });
                }
            }
        }
        out
    }

    /// The spec of a used texture, or [`SceneError::UnknownTexture`] naming the mesh.
    ///
    /// # Errors
    /// [`SceneError::UnknownTexture`] (validation already refuses such scenes).
    pub fn texture_spec(&self, u: &TextureUse) -> Result<&TextureSpec, SceneError> {
        self.textures
            .get(u.name)
            .ok_or_else(|| SceneError::UnknownTexture {
                mesh: u.mesh,
                name: u.name.to_string(),
                defined: self.textures.keys().cloned().collect::<Vec<_>>().join(", "),
            })
    }

    /// Load every texture of [`Scene::used_textures`] (unused ones are skipped), by name.
    /// `color_override` applies to colour textures only.
    ///
    /// # Errors
    /// As [`TextureSpec::load`].
    pub fn load_textures(
        &self,
        color_override: Option<ColorSpace>,
        limits: &Limits,
    ) -> Result<BTreeMap<String, Texture>, SceneError> {
        let mut out = BTreeMap::new();
        for u in self.used_textures() {
            let space = if u.color { color_override } else { None };
            let texture = self.texture_spec(&u)?.load(u.name, space, limits)?;
            out.insert(u.name.to_string(), texture);
        }
        Ok(out)
    }
}
