//! From a [`TextureSpec`] to a sampled [`Texture`].

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

use texel_texture::{ColorSpace, Limits, LoadOptions, Loaded, Texture};

use crate::error::SceneError;
use crate::model::{Scene, TextureSource, TextureSpec};
use crate::procedural::Procedural;

/// What decides the texels a [`TextureSpec`] loads to: its source (a file by its canonical
/// path, encoded bytes by their content, a generator by its parameters) and the colour space its
/// 8-bit values are read in. Specs with equal keys load to the same texture, whatever sampler
/// each brings; a file read as sRGB and the same file read as linear are two textures.
#[derive(Clone, PartialEq)]
pub struct TextureKey {
    source: KeySource,
    color: ColorSpace,
}

/// A texture source as [`TextureKey`] compares it.
#[derive(Clone)]
enum KeySource {
    /// A file, by its canonical path (the path as given where it cannot be resolved).
    File(PathBuf),
    /// Encoded bytes, equal when they are one allocation or hold the same bytes.
    Encoded(Arc<[u8]>),
    /// A generator and its parameters.
    Procedural(Procedural),
}

impl PartialEq for KeySource {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (KeySource::File(a), KeySource::File(b)) => a == b,
            (KeySource::Encoded(a), KeySource::Encoded(b)) => Arc::ptr_eq(a, b) || a[..] == b[..],
            (KeySource::Procedural(a), KeySource::Procedural(b)) => a == b,
            _ => false,
        }
    }
}

impl std::fmt::Debug for TextureKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.source {
            KeySource::File(p) => write!(f, "TextureKey({}, {:?})", p.display(), self.color),
            KeySource::Encoded(b) => write!(f, "TextureKey({} bytes, {:?})", b.len(), self.color),
            KeySource::Procedural(p) => write!(f, "TextureKey({p:?}, {:?})", self.color),
        }
    }
}

impl TextureSpec {
    /// The colour space used: `color_override` (the CLI's `--color raw` passes
    /// `Some(ColorSpace::Linear)`) or the spec's own.
    pub fn color_space(&self, color_override: Option<ColorSpace>) -> ColorSpace {
        color_override.unwrap_or(self.color)
    }

    /// What this spec loads to under `color_override` ([`TextureKey`]): file paths are
    /// canonicalized here, once per call.
    pub fn key(&self, color_override: Option<ColorSpace>) -> TextureKey {
        let source = match &self.source {
            TextureSource::File(p) => {
                KeySource::File(std::fs::canonicalize(p).unwrap_or_else(|_| p.clone()))
            }
            TextureSource::Encoded(e) => KeySource::Encoded(Arc::clone(&e.bytes)),
            TextureSource::Procedural(p) => KeySource::Procedural(*p),
        };
        TextureKey {
            source,
            color: self.color_space(color_override),
        }
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

/// Used textures ([`Scene::used_textures`]) that load to the same texels ([`TextureKey`]): one
/// load serves them all.
#[derive(Clone, Debug)]
pub struct TextureGroup<'a> {
    /// What the group's first use names: the spec to load.
    pub spec: &'a TextureSpec,
    /// The colour space every use of the group reads the spec in (pass it as the colour
    /// override of [`TextureSpec::load_with`]).
    pub color: ColorSpace,
    /// The uses, in first-use order (at least one).
    pub uses: Vec<TextureUse<'a>>,
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

    /// [`Scene::used_textures`] grouped by what they load to ([`TextureKey`]), in first-use
    /// order; `color_override` applies to colour textures only (as in [`Scene::load_textures`]).
    ///
    /// # Errors
    /// [`SceneError::UnknownTexture`] ([`Scene::texture_spec`]).
    pub fn texture_groups(
        &self,
        color_override: Option<ColorSpace>,
    ) -> Result<Vec<TextureGroup<'_>>, SceneError> {
        let mut groups: Vec<(TextureKey, TextureGroup)> = Vec::new();
        for u in self.used_textures() {
            let spec = self.texture_spec(&u)?;
            let space = if u.color { color_override } else { None };
            let key = spec.key(space);
            match groups.iter_mut().find(|(k, _)| *k == key) {
                Some((_, group)) => group.uses.push(u),
                None => groups.push((
                    key,
                    TextureGroup {
                        spec,
                        color: spec.color_space(space),
                        uses: vec![u],
                    },
                )),
            }
        }
        Ok(groups.into_iter().map(|(_, g)| g).collect())
    }

    /// Load every texture of [`Scene::used_textures`] (unused ones are skipped), by name: one
    /// load per [`Scene::texture_groups`] group, shared by the group's names.
    /// `color_override` applies to colour textures only.
    ///
    /// # Errors
    /// As [`TextureSpec::load`].
    pub fn load_textures(
        &self,
        color_override: Option<ColorSpace>,
        limits: &Limits,
    ) -> Result<BTreeMap<String, Arc<Texture>>, SceneError> {
        let mut out = BTreeMap::new();
        for group in self.texture_groups(color_override)? {
            let name = group.uses[0].name;
            let texture = Arc::new(group.spec.load(name, Some(group.color), limits)?);
            for u in &group.uses {
                out.insert(u.name.to_string(), Arc::clone(&texture));
            }
        }
        Ok(out)
    }
}
