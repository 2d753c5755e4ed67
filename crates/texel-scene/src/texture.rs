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

    /// As [`TextureSpec::load`]; with `replace_non_finite`, NaN and infinite float texels are
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

impl Scene {
    /// Load every texture the meshes and their materials use (unused ones are skipped), by name.
    /// `color_override` applies to colour textures; material maps other than `base_color`
    /// (normals, roughness, metalness) hold data and keep their own colour space.
    ///
    /// # Errors
    /// As [`TextureSpec::load`].
    pub fn load_textures(
        &self,
        color_override: Option<ColorSpace>,
        limits: &Limits,
    ) -> Result<BTreeMap<String, Texture>, SceneError> {
        let mut out = BTreeMap::new();
        for (mi, m) in self.meshes.iter().enumerate() {
            let mut wanted = vec![(m.texture.as_str(), color_override)];
            if let Some(mat) = m.material.as_ref().and_then(|n| self.materials.get(n)) {
                for t in mat.textures() {
                    if t != m.texture {
                        wanted.push((t, None));
                    }
                }
            }
            for (name, color) in wanted {
                if out.contains_key(name) {
                    continue;
                }
                let spec = self
                    .textures
                    .get(name)
                    .ok_or_else(|| SceneError::UnknownTexture {
                        mesh: mi,
                        name: name.to_string(),
                        defined: self.textures.keys().cloned().collect::<Vec<_>>().join(", "),
                    })?;
                out.insert(name.to_string(), spec.load(name, color, limits)?);
            }
        }
        Ok(out)
    }
}
