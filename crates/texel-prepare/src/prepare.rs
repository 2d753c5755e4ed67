//! A scene made ready to draw: textures decoded and their pyramids built once, meshes turned into
//! the rasterizer's vertices, the camera into `clip_from_world`, and one sampler per mesh for a
//! filter. The CLI, the examples, the GPU path, the viewer and the Python package all draw
//! through this.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Arc, Mutex, OnceLock};

use texel_raster::environment::{self, Environment, EnvironmentMaps};
use texel_raster::layers::{Layer, LayerBlend, Layers, MAX_LAYERS};
use texel_raster::material::MomentMap;
use texel_raster::{
    ChannelInput, ColorTarget, Displacement, DrawCall, Light, Material, Precision, RenderSettings,
    SpecularAa, TextureInput, UvEvaluation, UvMapping, Vertex,
};
use texel_scene::{
    ColorInput, LayerBlendSpec, LayerOrder, LightSpec, MaterialSpec, ScalarInput, Scene,
    SpecularAaSpec, TextureSampler,
};
use texel_texture::base::color::srgb_to_linear;
use texel_texture::{AddressMode, ColorSpace, Convention, Format, Limits, Sampler, Texture};

use crate::bake::{self, Composite};
use crate::memory::{raster_bytes, FRAME_BYTES_PER_PIXEL, TRIANGLE_BYTES, VERTEX_BYTES};
use crate::tessellate::Tessellated;
use crate::{Error, Filter, MemoryBudget};

// The scene schema's bound is the renderer's.
const _: () =
    assert!(texel_scene::MAX_SHADING_SAMPLES == texel_raster::material::MAX_SHADING_SAMPLES);

/// How 8-bit texture bytes and output bytes are interpreted (the CLI's `--color`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ColorHandling {
    /// Textures marked sRGB are decoded to linear light for filtering; output is sRGB-encoded.
    #[default]
    #[cfg_attr(
        feature = "clap",
        value(
            help = "Textures marked sRGB are decoded to linear light for filtering; output is sRGB-encoded"
        )
    )]
    Srgb,
    /// Every texture's bytes are linear and output bytes are linear (a GPU sampling plain RGBA8).
    #[cfg_attr(
        feature = "clap",
        value(
            help = "Every texture's bytes are linear; output bytes are linear (as a GPU sampling plain RGBA8)"
        )
    )]
    Raw,
}

impl ColorHandling {
    /// Both, in the order the command line lists them.
    pub const ALL: [ColorHandling; 2] = [ColorHandling::Srgb, ColorHandling::Raw];

    /// The name the command line, the scene files, Python and the reports use: `srgb` or `raw`.
    pub fn name(self) -> &'static str {
        match self {
            ColorHandling::Srgb => "srgb",
            ColorHandling::Raw => "raw",
        }
    }

    /// The 8-bit encoding of frames and images: sRGB-encoded RGB, or raw `round(255 x)`.
    pub fn encoding(self) -> texel_quality::Encoding {
        match self {
            ColorHandling::Srgb => texel_quality::Encoding::Srgb,
            ColorHandling::Raw => texel_quality::Encoding::Linear,
        }
    }

    /// How an 8-bit image read under this handling decodes: as sRGB, or as raw linear values.
    pub fn color_space(self) -> ColorSpace {
        match self {
            ColorHandling::Srgb => ColorSpace::Srgb,
            ColorHandling::Raw => ColorSpace::Linear,
        }
    }

    /// The 8-bit colour target a frame draws into: sRGB-encoded, or raw unorm.
    pub fn target(self) -> ColorTarget {
        match self {
            ColorHandling::Srgb => ColorTarget::Srgb8,
            ColorHandling::Raw => ColorTarget::Unorm8,
        }
    }

    /// An 8-bit value of a colour given under this handling (a scene's background), as the
    /// linear value it stands for.
    pub fn decode(self, value: u8) -> f32 {
        let v = f32::from(value) / 255.0;
        match self {
            ColorHandling::Srgb => srgb_to_linear(v),
            ColorHandling::Raw => v,
        }
    }
}

impl std::fmt::Display for ColorHandling {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for ColorHandling {
    type Err = String;

    /// `srgb` or `raw`, case ignored.
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|c| c.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| format!("unknown colour handling {s:?}: valid are srgb, raw"))
    }
}

/// How the scene's 8-bit textures are kept for the CPU's filters (the CLI's
/// `--texture-storage`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum TextureStorage {
    /// As they are stored: 4 bytes a texel, decoded at each read (a GPU's way).
    #[default]
    #[cfg_attr(
        feature = "clap",
        value(help = "8-bit texels, decoded at each read: 4 bytes a texel (a GPU's way)")
    )]
    Stored,
    /// Decoded once to linear `f32` ([`Texture::to_float`]): 16 bytes a texel, the same images,
    /// and faster mip and anisotropic filtering on CPUs whose caches hold the larger pyramids
    /// (docs/decisions.md, "Decoded float storage"). A texture whose float pyramid does not fit
    /// what the memory budget has left stays stored ([`PreparedScene::kept_stored`]); under
    /// [`Precision::Gpu`] unorm8 textures stay stored, since the fixed-point path reads codes.
    #[cfg_attr(
        feature = "clap",
        value(
            help = "Decoded once to linear f32: 16 bytes a texel, the same images, faster mip and anisotropic filtering"
        )
    )]
    Float,
}

impl TextureStorage {
    /// Every way, in the order help lists them.
    pub const ALL: [TextureStorage; 2] = [TextureStorage::Stored, TextureStorage::Float];

    /// The name the command line, Python and reports use: `stored` or `float`.
    pub fn name(self) -> &'static str {
        match self {
            TextureStorage::Stored => "stored",
            TextureStorage::Float => "float",
        }
    }
}

impl std::fmt::Display for TextureStorage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for TextureStorage {
    type Err = String;

    /// `stored` or `float`, case ignored.
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|t| t.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| format!("unknown texture storage {s:?}: valid are stored, float"))
    }
}

/// How a scene is prepared.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SceneOptions {
    /// Output size `(width, height)` in pixels, overriding the scene's.
    pub size: Option<(u32, u32)>,
    /// Colour handling.
    pub color: ColorHandling,
    /// Replace NaN, infinite and out-of-range float texels
    /// ([`texel_texture::replace_non_finite`]) instead of refusing the texture;
    /// [`PreparedScene::replaced`] reports how many.
    pub replace_non_finite: bool,
    /// Specular antialiasing for every material, overriding each one's `specular_aa` (the
    /// CLI's `--specular-aa`).
    pub specular_aa: Option<SpecularAa>,
    /// Adaptive shading sub-samples per pixel axis for every material, overriding each one's
    /// `shading_samples` (the CLI's `--shading-samples`; `1..=`[`texel_scene::MAX_SHADING_SAMPLES`]:
    /// larger values are clamped to the maximum and 0 to 1, one sample, as the CLI's own bounds
    /// check cannot reach this library call).
    pub shading_samples: Option<u32>,
    /// What every material's height map does, overriding each one's `displacement` (the CLI's
    /// `--displacement`; materials without a height map are unaffected).
    pub displacement: Option<texel_scene::Displacement>,
    /// The projected edge length, pixels, that `displacement = "tessellate"` tessellates to
    /// (the CLI's `--edge-px`); `None`: [`crate::tessellate::RENDER_EDGE_PX`].
    pub edge_px: Option<f32>,
    /// Where every layered material blends, overriding each one's `layer_order` (the CLI's
    /// `--layer-order`).
    pub layer_order: Option<LayerOrder>,
    /// The mapping the scene's procedural sky is laid out in, overriding its `mapping` (the
    /// CLI's `--environment-mapping`; a procedural sky is laid out again at the same texel angle).
    pub environment_mapping: Option<texel_scene::Mapping>,
    /// Where meshes with a sphere mapping (`sphere_uv`) get their uv: exactly per pixel (the
    /// default) or interpolated from the vertices (the CLI's `--surface-uv`).
    pub surface_uv: UvEvaluation,
    /// The filtering arithmetic for unorm8 textures in [`PreparedScene::settings`] (the CLI's
    /// `--precision`; the reference ignores it).
    pub precision: Precision,
    /// How 8-bit textures are kept (the CLI's `--texture-storage`): images do not depend on it.
    pub texture_storage: TextureStorage,
    /// The rules the lab's eight modes follow in [`PreparedScene::samplers`] (the CLI's
    /// `--convention`; [`texel_texture::Sampler::with_convention`]); the other filters have the
    /// GL rules only.
    pub convention: Convention,
}

/// `spec` with its procedural sky laid out in `mapping` at about the same texel angle: an
/// equirect map `W` wide becomes cube faces of `W / 4` or an octahedral square of `W / 2` (texel
/// angles `2 pi / W`, `8 / W` and `7.1 / W` radians), and back. `None` keeps `spec`.
///
/// # Errors
/// [`texel_scene::SceneError::Environment`] for a map from files in another mapping: their
/// layout is their own.
pub(crate) fn relay_sky(
    spec: &texel_scene::EnvironmentSpec,
    mapping: Option<texel_scene::Mapping>,
) -> Result<texel_scene::EnvironmentSpec, texel_scene::SceneError> {
    use texel_scene::{EnvironmentSource, Mapping};
    let Some(mapping) = mapping.filter(|m| *m != spec.mapping) else {
        return Ok(spec.clone());
    };
    let EnvironmentSource::Sky(sky) = &spec.source else {
        return Err(texel_scene::SceneError::Environment(format!(
            "the environment map is read from files laid out {:?}; only the procedural sky \
             can be laid out {:?} instead",
            spec.mapping.name(),
            mapping.name()
        )));
    };
    // Texels per equirect width.
    let per_width = |m: Mapping| match m {
        Mapping::Equirect => 1,
        Mapping::Cube => 4,
        Mapping::Octahedral => 2,
    };
    let width = (sky.width * per_width(spec.mapping) / per_width(mapping))
        .clamp(2, texel_scene::max_sky_width(mapping));
    Ok(texel_scene::EnvironmentSpec {
        mapping,
        source: EnvironmentSource::Sky(texel_scene::Sky { width, ..*sky }),
        ..spec.clone()
    })
}

/// A loaded scene, ready to render with any filter.
#[derive(Debug)]
pub struct PreparedScene {
    /// The scene as loaded.
    pub scene: Scene,
    /// Every texture the meshes use, by name, with its pyramid. Names whose specs load to the
    /// same texels ([`texel_scene::Scene::texture_groups`]: one glTF image, one file in one
    /// colour space) share one texture, loaded and charged once.
    pub textures: BTreeMap<String, Arc<Texture>>,
    /// Each mesh's vertices.
    pub vertices: Vec<Vec<Vertex>>,
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
    /// The colour handling the textures were loaded with.
    pub color: ColorHandling,
    /// Per texture, the non-finite channel values replaced (only with
    /// [`SceneOptions::replace_non_finite`]; textures with none are not listed; a shared texture
    /// under the first name that reads it).
    pub replaced: Vec<(String, u64)>,
    /// Textures that [`TextureStorage::Float`] left stored because their float pyramid did not
    /// fit what the memory budget had left, with the bytes it would have taken (a shared texture
    /// under the first name that reads it).
    pub kept_stored: Vec<(String, u64)>,
    /// The (texture, structure) pairs [`PreparedScene::build_structures_within`] has charged,
    /// each texture by its address (names that share a texture share its structures).
    charged: Mutex<BTreeSet<(usize, &'static str)>>,
    /// [`SceneOptions::precision`].
    pub precision: Precision,
    /// [`SceneOptions::convention`].
    pub convention: Convention,
    /// [`SceneOptions::specular_aa`].
    specular_aa: Option<SpecularAa>,
    /// [`SceneOptions::shading_samples`].
    shading_samples: Option<u32>,
    /// [`SceneOptions::displacement`].
    displacement: Option<texel_scene::Displacement>,
    /// LEAN moment maps ([`texel_raster::material::lean_map`]) of the normal maps of materials
    /// that use LEAN, by the normal map's texture name (one per shared texture).
    lean_maps: BTreeMap<String, Arc<MomentMap>>,
    /// Slope moment maps ([`texel_raster::material::height_moments`]) of the height maps of
    /// bump-mapped materials without a normal map that use LEAN or Toksvig, by texture name
    /// (one per shared texture).
    height_moments: BTreeMap<String, Arc<MomentMap>>,
    /// [`SceneOptions::layer_order`].
    layer_order: Option<LayerOrder>,
    /// [`SceneOptions::surface_uv`]; [`PreparedScene::set_surface_uv`] changes it.
    surface_uv: UvEvaluation,
    /// Baked layered materials ([`crate::bake`]), by material name: those that blend then
    /// filter, and those whose heights displace.
    composites: BTreeMap<String, Baked>,
    /// A 1x1 white texture: the draw's colour texture under a layered material that filters
    /// then blends (the layers give the colour).
    white: Texture,
    /// The distinct samplers of textures that bring their own ([`texel_scene::TextureSpec::sampler`], glTF
    /// textures), in the order [`PreparedScene::samplers`] lists them after the meshes'.
    own_samplers: Vec<TextureSampler>,
    /// Per texture with its own sampler, its index in `own_samplers`.
    own_sampler_of: BTreeMap<String, usize>,
    /// Per mesh, its tessellated and displaced geometry where its material tessellates
    /// (built for the scene's camera: other views reuse it).
    tessellated: Vec<Option<Tessellated>>,
    /// Per mesh, the reference's geometry where its material displaces at all: tessellated to
    /// [`crate::tessellate::REFERENCE_EDGE_PX`] and displaced by level-0 heights (built on first
    /// use).
    reference_geometry: OnceLock<Vec<Option<Tessellated>>>,
    /// The environment's maps ([`texel_raster::environment`]), when the scene has one.
    environment: Option<EnvironmentMaps>,
}

/// Load the environment map of `spec` within what `budget` has left and prefilter it (its
/// glossy pyramid and irradiance), charging both; with `replace_non_finite`, NaN, infinite and
/// out-of-range texels of its files are replaced (their count is returned) instead of refused.
fn environment_maps(
    spec: &texel_scene::EnvironmentSpec,
    budget: &mut MemoryBudget,
    replace_non_finite: bool,
) -> Result<(EnvironmentMaps, u64), Error> {
    let limits = budget.texture_limits();
    if let texel_scene::EnvironmentSource::Sky(sky) = &spec.source {
        // A procedural sky is charged before any of it is made: its layers' pyramids, the
        // texels of the layer being made, and the prefiltered maps.
        let (w, h) = sky.layer_size(spec.mapping);
        let f = texel_texture::Format::Rgba32Float.texel_bytes();
        let layer = texel_texture::storage::pyramid::pyramid_texels(w, h) * f;
        let made = u64::from(w) * u64::from(h) * f;
        let need = layer * spec.mapping.layers() as u64
            + made
            + EnvironmentMaps::extra_bytes(spec.mapping, w, h);
        if need > budget.remaining() {
            return Err(Error::OverBudget {
                what: format!("the procedural sky ({w}x{h} a layer) and its prefiltered maps"),
                bytes: need,
                used: budget.limit() - budget.remaining(),
                limit: budget.name().to_string(),
            });
        }
    }
    let (faces, replaced) = spec
        .load_with(&limits, replace_non_finite)
        .map_err(|e| budget.restate(e))?;
    budget.take(
        "the environment map",
        faces.iter().map(Texture::pyramid_bytes).sum(),
    )?;
    let (w, h) = (faces[0].width(), faces[0].height());
    budget.take(
        "the environment's prefiltered pyramid and irradiance",
        EnvironmentMaps::extra_bytes(spec.mapping, w, h),
    )?;
    let maps = EnvironmentMaps::new(spec.mapping, faces, &Limits::default())
        .map_err(texel_raster::RasterError::from)?;
    Ok((maps, replaced))
}

impl PreparedScene {
    /// How the scene's textures are kept, as reports write it: `stored`, `float` (8-bit textures
    /// decoded to float), or `float, N stored` when `N` of them did not fit the budget as float.
    pub fn storage_name(&self) -> String {
        let decoded = self
            .textures
            .values()
            .any(|t| t.format() != t.source_format());
        match (decoded, self.kept_stored.len()) {
            (false, 0) => "stored".into(),
            (true, 0) => "float".into(),
            (_, n) => format!("float, {n} stored"),
        }
    }

    /// Prepare `scene` (already validated, as [`Scene::load`] returns it): charge `budget` for
    /// the meshes and one frame of the output size, then load every texture the meshes use
    /// within what is left, charging each one's pyramid.
    ///
    /// # Errors
    /// [`Error::OverBudget`]; [`Error::Scene`] for a texture that cannot be loaded (its own memory
    /// limit is what the budget has left).
    pub fn new(
        mut scene: Scene,
        options: &SceneOptions,
        budget: &mut MemoryBudget,
    ) -> Result<Self, Error> {
        let (width, height) = options
            .size
            .unwrap_or((scene.output.width, scene.output.height));
        charge_geometry(&scene, (width, height), budget)?;
        let mut loaded = load_textures(&scene, options, budget)?;
        let kept_stored = store_textures(&mut loaded, options, budget)?;
        let Loaded {
            textures,
            names,
            mut replaced,
        } = loaded;
        let textures = share_textures(textures, names);
        if let Some(spec) = &scene.environment {
            scene.environment = Some(relay_sky(spec, options.environment_mapping)?);
        }
        let environment = match &scene.environment {
            Some(spec) => {
                let (maps, n) = environment_maps(spec, budget, options.replace_non_finite)?;
                if n > 0 {
                    replaced.push(("environment".to_string(), n));
                }
                Some(maps)
            }
            None => None,
        };
        let (own_samplers, own_sampler_of) = own_samplers(&scene)?;
        let derived = derive_maps(&scene, options, &textures, budget)?;
        generate_tangents(&mut scene);
        let vertices: Vec<Vec<Vertex>> = scene.meshes.iter().map(texel_vertices).collect();
        let tessellated = tessellate(
            &scene,
            &vertices,
            (&textures, &derived.composites),
            (width, height),
            options,
            budget,
        )?;
        let Derived {
            lean_maps,
            height_moments,
            composites,
        } = derived;
        Ok(PreparedScene {
            scene,
            textures,
            vertices,
            width,
            height,
            color: options.color,
            replaced,
            kept_stored,
            charged: Mutex::new(BTreeSet::new()),
            precision: options.precision,
            convention: options.convention,
            specular_aa: options.specular_aa,
            shading_samples: options.shading_samples,
            displacement: options.displacement,
            lean_maps,
            height_moments,
            layer_order: options.layer_order,
            surface_uv: options.surface_uv,
            composites,
            white: Texture::from_fn(
                1,
                1,
                texel_texture::Format::Rgba8Unorm,
                &Limits::default(),
                |_, _| [1.0; 4],
            )?,
            tessellated,
            reference_geometry: OnceLock::new(),
            own_samplers,
            own_sampler_of,
            environment,
        })
    }

    /// One sampler per mesh for `filter`, with each mesh's address modes; then one per distinct
    /// sampler that textures bring of their own (glTF textures' `wrapS`/`wrapT`), through which
    /// materials read those textures. Pass the whole list to [`PreparedScene::draws`]; a list
    /// of the meshes' alone reads every map through its mesh's sampler.
    ///
    /// # Errors
    /// [`Error::Texture`] if the descriptor is invalid (it never is for the built-in filters).
    pub fn samplers(&self, filter: Filter) -> Result<Vec<Sampler>, Error> {
        let meshes = self
            .scene
            .meshes
            .iter()
            .map(|m| (m.address_mode_u, m.address_mode_v));
        let own = self
            .own_samplers
            .iter()
            .map(|s| (s.address_mode_u, s.address_mode_v));
        let mut out: Vec<Sampler> = meshes
            .chain(own)
            .map(|(u, v)| {
                let s = Sampler::new(filter.descriptor(u, v))?;
                // The convention is a rule of the lab's eight modes; the other filters have one.
                Ok(match filter.lab_mode() {
                    Some(_) => s.with_convention(self.convention)?,
                    None => s,
                })
            })
            .collect::<Result<_, Error>>()?;
        self.push_environment_sampler(&mut out, filter)?;
        Ok(out)
    }

    /// Append the environment's sampler for `filter` (with its mapping's address modes) to
    /// `samplers`, when the scene has an environment.
    fn push_environment_sampler(
        &self,
        samplers: &mut Vec<Sampler>,
        filter: Filter,
    ) -> Result<(), Error> {
        if let Some(maps) = &self.environment {
            let desc = filter.descriptor(AddressMode::ClampToEdge, AddressMode::ClampToEdge);
            samplers.push(Sampler::new(environment::descriptor(
                maps.layout.mapping,
                desc,
            ))?);
        }
        Ok(())
    }

    /// The samplers of [`PreparedScene::samplers`] when no filter is named: a glTF mesh's or
    /// texture's own sampler filters (`magFilter`/`minFilter`; what the glTF leaves unspecified
    /// is linear, as for trilinear), and trilinear for every other mesh.
    ///
    /// # Errors
    /// [`Error::Texture`] for an invalid combination from the glTF file.
    pub fn default_samplers(&self) -> Result<Vec<Sampler>, Error> {
        let meshes = self
            .scene
            .meshes
            .iter()
            .map(|m| (m.address_mode_u, m.address_mode_v, m.filters));
        let own = self
            .own_samplers
            .iter()
            .map(|s| (s.address_mode_u, s.address_mode_v, Some(s.filters)));
        let mut out: Vec<Sampler> = meshes
            .chain(own)
            .map(|(u, v, filters)| {
                let mut desc = Filter::Trilinear.descriptor(u, v);
                if let Some(f) = &filters {
                    desc.mag_filter = f.mag_filter.unwrap_or(desc.mag_filter);
                    desc.min_filter = f.min_filter.unwrap_or(desc.min_filter);
                    desc.mipmap_filter = f.mipmap_filter.unwrap_or(desc.mipmap_filter);
                }
                Ok(Sampler::new(desc)?)
            })
            .collect::<Result<_, Error>>()?;
        self.push_environment_sampler(&mut out, Filter::Trilinear)?;
        Ok(out)
    }

    /// The scene's environment as a frame seen by `camera` reads it, through the last of
    /// `samplers` (those of [`PreparedScene::samplers`], which end with the environment's when
    /// there is one); `None` for a scene without one.
    pub fn environment<'a>(
        &'a self,
        samplers: &'a [Sampler],
        camera: &texel_scene::Camera,
    ) -> Option<Environment<'a>> {
        let aspect = self.width as f32 / self.height as f32;
        self.environment_through(samplers, camera.clip_from_world(aspect))
    }

    /// [`PreparedScene::environment`] with the background seen through `clip_from_world` (the
    /// viewer's fly camera at its own aspect).
    pub fn environment_through<'a>(
        &'a self,
        samplers: &'a [Sampler],
        clip_from_world: glam::Mat4,
    ) -> Option<Environment<'a>> {
        let maps = self.environment.as_ref()?;
        let spec = self.scene.environment.as_ref()?;
        Some(Environment {
            maps,
            sampler: samplers.last()?,
            intensity: spec.intensity,
            background: spec.background,
            clip_from_world,
        })
    }

    /// Build the acceleration structures `samplers` need (ripmaps, summed-area tables) ahead of
    /// drawing, and return the bytes of every structure the frame uses (pyramids included),
    /// counting each texture once (names that share a texture count it once).
    ///
    /// # Errors
    /// [`Error::Texture`] when a structure does not fit the texture's memory limit.
    pub fn build_structures(&self, samplers: &[Sampler]) -> Result<u64, Error> {
        let mut bytes = BTreeMap::new();
        for (mesh, sampler) in self.scene.meshes.iter().zip(samplers) {
            let tex = &self.textures[&mesh.texture];
            tex.build_structures(sampler)?;
            let b = tex.structure_bytes(sampler.descriptor());
            let e = bytes.entry(Arc::as_ptr(tex) as usize).or_insert(0u64);
            *e = (*e).max(b);
        }
        Ok(bytes.values().sum())
    }

    /// [`PreparedScene::build_structures`], charging `budget` for each ripmap and summed-area
    /// table before it is built (once per texture and kind, names that share a texture sharing
    /// its structures: they are kept for later frames), and for a ripmap's build scratch while
    /// it is built ([`Texture::build_scratch_bytes`]).
    ///
    /// # Errors
    /// [`Error::OverBudget`], for the budget's refusal and for a texture's own (its limits were
    /// what the budget had left when it loaded: [`MemoryBudget::restate`], with the build's
    /// scratch), and those of [`PreparedScene::build_structures`].
    pub fn build_structures_within(
        &self,
        samplers: &[Sampler],
        budget: &mut MemoryBudget,
    ) -> Result<u64, Error> {
        for (mesh, sampler) in self.scene.meshes.iter().zip(samplers) {
            let kind = match sampler.descriptor().min_filter {
                texel_texture::FilterMode::Ripmap => "ripmap",
                texel_texture::FilterMode::SummedArea => "summed-area table",
                _ => continue,
            };
            let tex = &self.textures[&mesh.texture];
            let key = (Arc::as_ptr(tex) as usize, kind);
            let mut charged = self.charged.lock().unwrap_or_else(|e| e.into_inner());
            if charged.contains(&key) {
                continue;
            }
            let extra = tex.structure_bytes(sampler.descriptor()) - tex.pyramid_bytes();
            let scratch = tex.build_scratch_bytes(sampler.descriptor());
            let with = if scratch > 0 {
                " with its build scratch"
            } else {
                ""
            };
            budget.take(
                &format!("the {kind} of texture {:?}{with}", mesh.texture),
                extra.saturating_add(scratch),
            )?;
            let built = tex.build_structures(sampler);
            budget.release(scratch);
            if let Err(source) = built {
                budget.release(extra);
                return Err(budget.restate(texel_scene::SceneError::Texture {
                    name: mesh.texture.clone(),
                    path: None,
                    source,
                }));
            }
            charged.insert(key);
        }
        self.build_structures(samplers)
    }

    /// Where meshes with a sphere mapping get their uv from now on ([`SceneOptions::surface_uv`]).
    pub fn set_surface_uv(&mut self, evaluation: UvEvaluation) {
        self.surface_uv = evaluation;
    }

    /// Whether some mesh has a sphere mapping that its draws evaluate per pixel.
    pub fn maps_uv_per_pixel(&self) -> bool {
        self.surface_uv == UvEvaluation::PerPixel
            && self.scene.meshes.iter().any(|m| m.uv_mapping.is_some())
    }

    /// The draw calls of the whole scene with `samplers` (one per mesh), seen by the scene's
    /// camera.
    pub fn draws<'a>(&'a self, samplers: &'a [Sampler]) -> Vec<DrawCall<'a>> {
        self.draws_from(samplers, &self.scene.camera)
    }

    /// [`PreparedScene::draws`] seen by `camera` instead (an orbit, the viewer's fly camera).
    pub fn draws_from<'a>(
        &'a self,
        samplers: &'a [Sampler],
        camera: &texel_scene::Camera,
    ) -> Vec<DrawCall<'a>> {
        self.draws_over(samplers, camera, &self.tessellated, false)
    }

    /// The draw calls the reference renders, seen by `camera`: [`PreparedScene::draws_from`],
    /// except that meshes whose material displaces (bump, parallax or tessellation, in the scene
    /// file or by [`SceneOptions::displacement`]; `none` as an override still shows the relief
    /// it leaves out) are drawn as
    /// the true displaced surface, tessellated finely ([`crate::tessellate::REFERENCE_EDGE_PX`]
    /// for the scene's camera) and displaced by level-0 heights, with the exact normals of the
    /// height map (bump mapping at level 0): what every displacement method approximates.
    ///
    /// # Errors
    /// [`Error::Scene`] when the fine tessellation would pass its triangle limit.
    pub fn reference_draws_from<'a>(
        &'a self,
        samplers: &'a [Sampler],
        camera: &texel_scene::Camera,
    ) -> Result<Vec<DrawCall<'a>>, Error> {
        if self.reference_geometry.get().is_none() {
            let options = SceneOptions {
                displacement: self.displacement,
                ..SceneOptions::default()
            };
            let mut built = Vec::new();
            for (mesh, verts) in self.scene.meshes.iter().zip(&self.vertices) {
                built.push(displaced_geometry(
                    &self.scene,
                    mesh,
                    verts,
                    heights_of(mesh, &self.scene, &self.textures, &self.composites),
                    (self.width, self.height),
                    &options,
                    Geometry::Reference,
                )?);
            }
            // Another thread may have set it meanwhile: either copy is the same.
            let _ = self.reference_geometry.set(built);
        }
        let geometry = self.reference_geometry.get().map_or(&[][..], Vec::as_slice);
        Ok(self.draws_over(samplers, camera, geometry, true))
    }

    /// Draws over each mesh's own geometry, or `geometry[k]` where it is given; with `exact` (the
    /// reference), meshes drawn from `geometry` shade with the bump normals of their heights and
    /// layered materials blend their layers per sample, baked or not.
    fn draws_over<'a>(
        &'a self,
        samplers: &'a [Sampler],
        camera: &texel_scene::Camera,
        geometry: &'a [Option<Tessellated>],
        exact: bool,
    ) -> Vec<DrawCall<'a>> {
        let aspect = self.width as f32 / self.height as f32;
        let clip_from_world = camera.clip_from_world(aspect);
        let own_samplers = samplers.get(self.scene.meshes.len()..).unwrap_or(&[]);
        self.scene
            .meshes
            .iter()
            .enumerate()
            .zip(samplers)
            .map(|((k, mesh), sampler)| {
                let own = geometry.get(k).and_then(Option::as_ref);
                let maps = MapInputs {
                    textures: &self.textures,
                    mesh: sampler,
                    own: own_samplers,
                    own_of: &self.own_sampler_of,
                };
                let mut material = self.material(mesh, maps, exact);
                if let (Some(m), true, Some(_)) = (&mut material, exact, own) {
                    m.displacement = Displacement::Bump;
                }
                DrawCall {
                    vertices: own.map_or(&self.vertices[k][..], |g| &g.vertices[..]),
                    triangles: own.map_or(&mesh.triangles[..], |g| &g.triangles[..]),
                    texture: self.draw_texture(mesh, exact),
                    sampler,
                    clip_from_world,
                    material,
                    // Tessellated (displaced) geometry keeps the mapping at its vertices only:
                    // its points are no longer on the sphere.
                    uv_mapping: mesh
                        .uv_mapping
                        .filter(|_| own.is_none())
                        .map(|m| UvMapping {
                            projection: m.projection,
                            centre: m.centre,
                            evaluation: self.surface_uv,
                        }),
                }
            })
            .collect()
    }

    /// The colour texture `mesh` is drawn with: its own, or for a layered material the baked
    /// base colour (blend then filter) or white (filter then blend, and the reference, which
    /// blends every sub-sample: the layers give the colour).
    fn draw_texture(&self, mesh: &texel_scene::Mesh, reference: bool) -> &Texture {
        let layered = mesh
            .material
            .as_ref()
            .and_then(|n| Some((n, self.scene.materials.get(n)?)))
            .filter(|(_, spec)| !spec.layers.is_empty());
        match layered {
            Some((name, spec)) => match self.baked(name, spec).filter(|_| !reference) {
                Some(b) => &b.composite.base,
                None => &self.white,
            },
            None => &self.textures[&mesh.texture],
        }
    }

    /// The baked maps of layered material `name` where it blends then filters.
    fn baked(&self, name: &str, spec: &MaterialSpec) -> Option<&Baked> {
        let order = self.layer_order.unwrap_or(spec.layer_order);
        (order == LayerOrder::BlendThenFilter)
            .then(|| self.composites.get(name))
            .flatten()
    }

    /// The rasterizer's material of `mesh`, its maps read through `maps`; for the
    /// `reference`, layered materials blend their layers (per sub-sample) even where they are
    /// baked.
    fn material<'a>(
        &'a self,
        mesh: &texel_scene::Mesh,
        maps: MapInputs<'a>,
        reference: bool,
    ) -> Option<Material<'a>> {
        let name = mesh.material.as_ref()?;
        let spec = self.scene.materials.get(name)?;
        let sampler = maps.mesh;
        let channel = |texture: &'a Texture| red(texture, sampler);
        let (roughness, roughness_map) = maps.scalar(&spec.roughness);
        let (metallic, metallic_map) = maps.scalar(&spec.metallic);
        let base_color = match spec.base_color {
            ColorInput::Rgb(c) => c.extend(1.0),
            ColorInput::Texture(_) => glam::Vec4::ONE,
        };
        let mut specular_aa = specular_aa(spec, self.specular_aa);
        let shape = match displacement(spec, self.displacement) {
            texel_scene::Displacement::None => Displacement::None,
            texel_scene::Displacement::Bump => Displacement::Bump,
            texel_scene::Displacement::Pom => Displacement::Pom,
            // Tessellated geometry is displaced before drawing; its normal is the bump map's.
            texel_scene::Displacement::Tessellate => Displacement::Bump,
        };
        let mut m = Material {
            base_color,
            roughness,
            metallic,
            roughness_map,
            metallic_map,
            normal_map: spec.normal.as_deref().map(|n| maps.input(n)),
            normal_scale: spec.normal_scale,
            specular_aa,
            shading_samples: self
                .shading_samples
                .unwrap_or(spec.shading_samples)
                .clamp(1, texel_scene::MAX_SHADING_SAMPLES),
            lean: spec
                .normal
                .as_ref()
                .and_then(|n| self.lean_maps.get(n))
                .map(Arc::as_ref),
            height_map: spec.height.as_deref().map(|h| maps.red(h)),
            height_scale: spec.height_scale,
            displacement: Displacement::None,
            height_moments: spec
                .height
                .as_ref()
                .and_then(|h| self.height_moments.get(h))
                .map(Arc::as_ref),
            layers: None,
            occlusion_map: spec.occlusion.as_deref().map(|o| maps.red(o)),
            occlusion_strength: spec.occlusion_strength,
        };
        if !spec.layers.is_empty() {
            // The layers give the roughness (validation keeps the material's own at its default).
            m.roughness = 1.0;
        }
        if let Some(b) = self.baked(name, spec).filter(|_| !reference) {
            // Blend then filter: the baked maps are an ordinary material's.
            let c = &b.composite;
            m.roughness_map = Some(channel(&c.roughness));
            m.normal_map = c
                .normal
                .as_ref()
                .map(|texture| TextureInput { texture, sampler });
            m.normal_scale = 1.0;
            m.lean = b.lean.as_ref();
            m.height_map = c.height.as_ref().map(channel);
            m.height_moments = b.slope_moments.as_ref();
        } else if !spec.layers.is_empty() {
            m.layers = Some(layers_of(spec, maps, &self.lean_maps));
        }
        if m.has_height() {
            m.displacement = shape;
        }
        let moments = m.lean.is_some()
            || m.height_moments.is_some()
            || m.layers.as_ref().is_some_and(Layers::has_normals);
        if specular_aa == SpecularAa::Lean && !moments {
            // No normal or bump map: nothing varies within a pixel to antialias.
            specular_aa = SpecularAa::None;
        }
        m.specular_aa = specular_aa;
        Some(m)
    }

    /// Render settings for this scene's size, background (decoded as the colour handling says),
    /// lights, precision ([`SceneOptions::precision`]) and colour target: the 8-bit target the
    /// colour handling encodes to
    /// ([`ColorTarget::Srgb8`] for [`ColorHandling::Srgb`], [`ColorTarget::Unorm8`] for
    /// [`ColorHandling::Raw`]), so a frame holds the bytes a PNG of it holds. Set
    /// `target = ColorTarget::Float` for linear floats (accumulating, comparing before
    /// quantisation).
    pub fn settings(&self) -> RenderSettings<'static> {
        let mut s = RenderSettings::new(self.width, self.height);
        s.target = self.color.target();
        s.precision = self.precision;
        for (slot, light) in s.lights.iter_mut().zip(&self.scene.lights) {
            *slot = Some(match *light {
                LightSpec::Directional {
                    direction,
                    intensity,
                } => Light::Directional {
                    direction: shading_direction(direction),
                    intensity,
                },
                LightSpec::Point {
                    position,
                    intensity,
                } => Light::Point {
                    position,
                    intensity,
                },
                LightSpec::Ambient { intensity } => Light::Ambient { intensity },
            });
        }
        let bg = self.scene.output.background;
        s.background = [
            self.color.decode(bg[0]),
            self.color.decode(bg[1]),
            self.color.decode(bg[2]),
            f32::from(bg[3]) / 255.0,
        ];
        s
    }

    /// [`PreparedScene::settings`] with the scene's environment as `camera` sees it through the
    /// last of `samplers` ([`PreparedScene::environment`]): what every frame of the scene
    /// renders with.
    pub fn settings_for<'a>(
        &'a self,
        samplers: &'a [Sampler],
        camera: &texel_scene::Camera,
    ) -> RenderSettings<'a> {
        let mut s = self.settings();
        s.environment = self.environment(samplers, camera);
        s
    }
}

/// Charge `budget` for `scene`'s meshes, for rasterizing them at `(width, height)` and for one
/// frame of that size.
fn charge_geometry(
    scene: &Scene,
    (width, height): (u32, u32),
    budget: &mut MemoryBudget,
) -> Result<(), Error> {
    let (verts, tris) = scene.meshes.iter().fold((0u64, 0u64), |(v, t), m| {
        (v + m.positions.len() as u64, t + m.triangles.len() as u64)
    });
    budget.take("the meshes", verts * VERTEX_BYTES + tris * TRIANGLE_BYTES)?;
    budget.take(
        &format!("rasterizing {tris} triangles at {width}x{height}"),
        raster_bytes(scene, width, height),
    )?;
    budget.take(
        &format!("a {width}x{height} frame"),
        u64::from(width) * u64::from(height) * FRAME_BYTES_PER_PIXEL,
    )?;
    Ok(())
}

/// Textures by name, names that load to the same texels sharing one.
type Textures = BTreeMap<String, Arc<Texture>>;

/// Moment maps by texture name, names that share a texture sharing one.
type MomentMaps = BTreeMap<String, Arc<MomentMap>>;

/// The distinct textures a scene's meshes use ([`load_textures`]).
struct Loaded {
    /// One texture per group of names whose specs load to the same texels.
    textures: Vec<Texture>,
    /// Per texture, the names that read it (the first one names it in messages).
    names: Vec<Vec<String>>,
    /// The textures whose non-finite texels were replaced, by first name, with their counts.
    replaced: Vec<(String, u64)>,
}

/// Every texture the meshes use, loaded once per group of names whose specs load to the same
/// texels ([`Scene::texture_groups`]), each within what `budget` has left and charged its
/// pyramid once.
fn load_textures(
    scene: &Scene,
    options: &SceneOptions,
    budget: &mut MemoryBudget,
) -> Result<Loaded, Error> {
    let override_space = match options.color {
        ColorHandling::Srgb => None,
        ColorHandling::Raw => Some(ColorSpace::Linear),
    };
    let mut out = Loaded {
        textures: Vec::new(),
        names: Vec::new(),
        replaced: Vec::new(),
    };
    for group in scene.texture_groups(override_space)? {
        let name = group.uses[0].name;
        let limits = budget.texture_limits();
        let loaded = group
            .spec
            .load_with(name, Some(group.color), &limits, options.replace_non_finite)
            .map_err(|e| budget.restate(e))?;
        if loaded.replaced > 0 {
            out.replaced.push((name.to_string(), loaded.replaced));
        }
        let what = match group.uses.len() {
            1 => format!("texture {name:?}"),
            n => format!("texture {name:?} (shared by {n} names)"),
        };
        budget.take(&what, loaded.texture.pyramid_bytes())?;
        out.textures.push(loaded.texture);
        out.names
            .push(group.uses.iter().map(|u| u.name.to_string()).collect());
    }
    Ok(out)
}

/// The textures by name: each of `textures` under every one of its `names`, shared.
fn share_textures(
    textures: Vec<Texture>,
    names: Vec<Vec<String>>,
) -> BTreeMap<String, Arc<Texture>> {
    let mut out = BTreeMap::new();
    for (texture, names) in textures.into_iter().zip(names) {
        let texture = Arc::new(texture);
        for name in names {
            out.insert(name, Arc::clone(&texture));
        }
    }
    out
}

/// Keep the `loaded` textures as `options.texture_storage` asks: with [`TextureStorage::Float`]
/// each 8-bit texture is replaced by its float copy where the copy fits what `budget` has left
/// (charged while both exist, the 8-bit pyramid released after); the first names and float
/// bytes of those that did not fit. A copy that fits the budget fits its texture's own limits
/// too: those were what the budget had left when the texture was loaded, before its own pyramid
/// was charged.
fn store_textures(
    loaded: &mut Loaded,
    options: &SceneOptions,
    budget: &mut MemoryBudget,
) -> Result<Vec<(String, u64)>, Error> {
    let mut kept = Vec::new();
    if options.texture_storage == TextureStorage::Stored {
        return Ok(kept);
    }
    for (texture, names) in loaded.textures.iter_mut().zip(&loaded.names) {
        let name = &names[0];
        let format = texture.format();
        let codes_read = options.precision == Precision::Gpu && format == Format::Rgba8Unorm;
        if format == Format::Rgba32Float || codes_read {
            continue;
        }
        let (stored, float) = (texture.pyramid_bytes(), texture.float_pyramid_bytes());
        if float > budget.remaining() {
            kept.push((name.clone(), float));
            continue;
        }
        budget.take(&format!("texture {name:?} as float"), float)?;
        *texture = texture.to_float()?;
        budget.release(stored);
    }
    Ok(kept)
}

/// The distinct samplers textures bring of their own (glTF textures' `wrapS`/`wrapT`), and
/// which of them each such texture is read through.
fn own_samplers(scene: &Scene) -> Result<(Vec<TextureSampler>, BTreeMap<String, usize>), Error> {
    let mut own_samplers: Vec<TextureSampler> = Vec::new();
    let mut own_sampler_of = BTreeMap::new();
    for u in scene.used_textures() {
        let Some(own) = scene.texture_spec(&u)?.sampler else {
            continue;
        };
        let i = match own_samplers.iter().position(|s| *s == own) {
            Some(i) => i,
            None => {
                own_samplers.push(own);
                own_samplers.len() - 1
            }
        };
        own_sampler_of.insert(u.name.to_string(), i);
    }
    Ok((own_samplers, own_sampler_of))
}

/// The maps a scene's materials derive from their textures ([`derive_maps`]).
struct Derived {
    /// LEAN moment maps of normal maps, by texture name.
    lean_maps: BTreeMap<String, Arc<MomentMap>>,
    /// Slope moment maps of height maps, by texture name.
    height_moments: BTreeMap<String, Arc<MomentMap>>,
    /// Baked layered materials, by material name.
    composites: BTreeMap<String, Baked>,
}

/// The maps the materials derive, each charged to `budget`. LEAN reads moment maps made from
/// the normal maps (a layered material's too), and LEAN and Toksvig on bump maps moment maps
/// made from the height maps (float, charged like any texture). Layered materials that blend
/// then filter, or whose heights displace, are baked ([`bake_layers`]).
fn derive_maps(
    scene: &Scene,
    options: &SceneOptions,
    textures: &BTreeMap<String, Arc<Texture>>,
    budget: &mut MemoryBudget,
) -> Result<Derived, Error> {
    let mut derived = Derived {
        lean_maps: BTreeMap::new(),
        height_moments: BTreeMap::new(),
        composites: BTreeMap::new(),
    };
    // Each moment map made, by its texture's address: names that share a texture share it.
    let mut made: Vec<(usize, Moments, Arc<MomentMap>)> = Vec::new();
    for (material, mat) in &scene.materials {
        let aa = specular_aa(mat, options.specular_aa);
        let shape = displacement(mat, options.displacement);
        let bumped = shape != texel_scene::Displacement::None;
        let jobs: Vec<(&String, Moments)> = if !mat.layers.is_empty() {
            let normals = mat.layers.iter().filter_map(|l| l.normal.as_ref());
            let lean = aa == SpecularAa::Lean;
            normals
                .filter(|_| lean)
                .map(|n| (n, Moments::Lean))
                .collect()
        } else {
            moment_source(aa, bumped, mat.normal.as_ref(), mat.height.as_ref())
                .into_iter()
                .collect()
        };
        for (name, kind) in jobs {
            let out = match kind {
                Moments::Lean => &mut derived.lean_maps,
                Moments::Slopes => &mut derived.height_moments,
            };
            let Some(map) = textures.get(name) else {
                continue;
            };
            if !out.contains_key(name) {
                let address = Arc::as_ptr(map) as usize;
                let moments = match made.iter().find(|(a, k, _)| *a == address && *k == kind) {
                    Some((_, _, m)) => Arc::clone(m),
                    None => {
                        let m = Arc::new(moment_map(kind, map, budget, name)?);
                        made.push((address, kind, Arc::clone(&m)));
                        m
                    }
                };
                out.insert(name.clone(), moments);
            }
        }
        let order = options.layer_order.unwrap_or(mat.layer_order);
        let displaced = bumped || mat.displacement != texel_scene::Displacement::None;
        let wanted = order == LayerOrder::BlendThenFilter || (displaced && mat.layer_heights());
        if mat.layers.is_empty() || !wanted {
            continue;
        }
        let maps = (textures, &derived.lean_maps);
        let baked = bake_layers(scene, (material, mat), maps, (aa, bumped), budget)?;
        derived.composites.insert(material.clone(), baked);
    }
    Ok(derived)
}

/// Material `mat` (named `material`) with its layers baked into one set of maps through a
/// level-0 sampler with its mesh's address modes, charged to `budget`, and the moment map its
/// specular antialiasing `aa` reads of the baked normals or (where `bumped`) heights.
fn bake_layers(
    scene: &Scene,
    (material, mat): (&String, &texel_scene::MaterialSpec),
    (textures, lean_maps): (&Textures, &MomentMaps),
    (aa, bumped): (SpecularAa, bool),
    budget: &mut MemoryBudget,
) -> Result<Baked, Error> {
    let modes = scene
        .meshes
        .iter()
        .find(|m| m.material.as_ref() == Some(material))
        .map_or((AddressMode::Repeat, AddressMode::Repeat), |m| {
            (m.address_mode_u, m.address_mode_v)
        });
    let level0 = bake::level0_sampler(modes)?;
    let maps = MapInputs {
        textures,
        mesh: &level0,
        own: &[],
        own_of: &BTreeMap::new(),
    };
    let layers = layers_of(mat, maps, lean_maps);
    let limits = budget.texture_limits();
    let what = format!("{material} (its layers baked)");
    let composite = bake::bake(&layers, &level0, &limits).map_err(|source| {
        budget.restate(texel_scene::SceneError::Texture {
            name: what.clone(),
            path: None,
            source,
        })
    })?;
    budget.take(
        &format!("the baked layers of material {material:?}"),
        composite.bytes(),
    )?;
    let mut baked = Baked {
        lean: None,
        slope_moments: None,
        composite,
    };
    let c = &baked.composite;
    if let Some((map, kind)) = moment_source(aa, bumped, c.normal.as_ref(), c.height.as_ref()) {
        let moments = Some(moment_map(kind, map, budget, &what)?);
        match kind {
            Moments::Lean => baked.lean = moments,
            Moments::Slopes => baked.slope_moments = moments,
        }
    }
    Ok(baked)
}

/// Normal maps need tangents: MikkTSpace where the mesh brings none.
fn generate_tangents(scene: &mut Scene) {
    for m in &mut scene.meshes {
        let mapped = m
            .material
            .as_ref()
            .and_then(|n| scene.materials.get(n))
            .is_some_and(|mat| {
                mat.normal.is_some() || mat.layers.iter().any(|l| l.normal.is_some())
            });
        if mapped && m.tangents.is_none() {
            m.generate_tangents();
        }
    }
}

/// Each mesh's displaced geometry for rendering at `size` (`None` where its material does not
/// tessellate), charged to `budget`.
fn tessellate(
    scene: &Scene,
    vertices: &[Vec<Vertex>],
    (textures, composites): (&BTreeMap<String, Arc<Texture>>, &BTreeMap<String, Baked>),
    size: (u32, u32),
    options: &SceneOptions,
    budget: &mut MemoryBudget,
) -> Result<Vec<Option<Tessellated>>, Error> {
    let mut tessellated = Vec::new();
    for (mesh, verts) in scene.meshes.iter().zip(vertices) {
        let geometry = displaced_geometry(
            scene,
            mesh,
            verts,
            heights_of(mesh, scene, textures, composites),
            size,
            options,
            Geometry::Render,
        )?;
        if let Some(g) = &geometry {
            budget.take(
                "the tessellated geometry",
                g.vertices.len() as u64 * VERTEX_BYTES + g.triangles.len() as u64 * TRIANGLE_BYTES,
            )?;
        }
        tessellated.push(geometry);
    }
    Ok(tessellated)
}

/// The specular antialiasing a material gets: `overridden` (the CLI's `--specular-aa`) or its own.
fn specular_aa(spec: &texel_scene::MaterialSpec, overridden: Option<SpecularAa>) -> SpecularAa {
    overridden.unwrap_or(match spec.specular_aa {
        SpecularAaSpec::Toksvig => SpecularAa::Toksvig,
        SpecularAaSpec::Lean => SpecularAa::Lean,
        SpecularAaSpec::Projected => SpecularAa::Projected,
        SpecularAaSpec::None => SpecularAa::None,
    })
}

/// Which displaced geometry [`displaced_geometry`] builds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Geometry {
    /// `displacement = "tessellate"`: to the options' edge length, heights filtered to it.
    Render,
    /// The reference's: for every displacement, finely, level-0 heights.
    Reference,
}

/// The tessellated, displaced geometry of `mesh` (whose vertices are `verts`) for `kind`, or
/// `None` where its material does not ask for it.
fn displaced_geometry(
    scene: &Scene,
    mesh: &texel_scene::Mesh,
    verts: &[Vertex],
    heights: Option<&Texture>,
    (width, height): (u32, u32),
    options: &SceneOptions,
    kind: Geometry,
) -> Result<Option<Tessellated>, Error> {
    use crate::tessellate::{self, HeightFilter};
    use texel_scene::Displacement as D;
    let Some(spec) = mesh.material.as_ref().and_then(|n| scene.materials.get(n)) else {
        return Ok(None);
    };
    let Some(heights) = heights else {
        return Ok(None);
    };
    let shape = displacement(spec, options.displacement);
    // The reference shows the true relief when the scene's material or the override displaces:
    // `--displacement none` is then scored against the relief it leaves out.
    let truth = spec.displacement != D::None || shape != D::None;
    let (edge_px, filter) = match (kind, shape) {
        (Geometry::Reference, _) if !truth => return Ok(None),
        (Geometry::Render, D::None | D::Bump | D::Pom) => return Ok(None),
        (Geometry::Render, D::Tessellate) => (
            options.edge_px.unwrap_or(tessellate::RENDER_EDGE_PX),
            HeightFilter::EdgeMatched,
        ),
        (Geometry::Reference, _) => (tessellate::REFERENCE_EDGE_PX, HeightFilter::Level0),
    };
    let setup = tessellate::Tessellation {
        clip_from_world: scene.camera.clip_from_world(width as f32 / height as f32),
        width,
        height,
        edge_px,
        max_triangles: MAX_TESSELLATED_TRIANGLES,
    };
    let mut geometry = tessellate::tessellate(verts, &mesh.triangles, &setup).map_err(|e| {
        texel_scene::SceneError::Material {
            name: mesh.material.clone().unwrap_or_default(),
            reason: format!("{e} (at {edge_px} pixels per edge): raise --edge-px or lower --size"),
        }
    })?;
    tessellate::displace(
        &mut geometry,
        heights,
        (mesh.address_mode_u, mesh.address_mode_v),
        spec.height_scale,
        filter,
    )?;
    Ok(Some(geometry))
}

/// The height map that displaces `mesh`: its material's, or the baked heights of its layers.
fn heights_of<'a>(
    mesh: &texel_scene::Mesh,
    scene: &Scene,
    textures: &'a BTreeMap<String, Arc<Texture>>,
    composites: &'a BTreeMap<String, Baked>,
) -> Option<&'a Texture> {
    let name = mesh.material.as_ref()?;
    let spec = scene.materials.get(name)?;
    match &spec.height {
        Some(h) => textures.get(h).map(Arc::as_ref),
        None => composites.get(name)?.composite.height.as_ref(),
    }
}

/// A baked layered material and the moment maps its specular antialiasing reads.
#[derive(Debug)]
struct Baked {
    composite: Composite,
    /// LEAN moments of the baked normals.
    lean: Option<MomentMap>,
    /// Slope moments of the baked heights (bump-mapped, without normals).
    slope_moments: Option<MomentMap>,
}

/// The two kinds of moment map specular antialiasing reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Moments {
    /// LEAN's moments of a normal map ([`texel_raster::material::lean_map`]).
    Lean,
    /// The slope moments of a height map ([`texel_raster::material::height_moments`]).
    Slopes,
}

/// The moment map a material with these maps reads under specular antialiasing `aa`: LEAN's of
/// its normal map; or, bump-mapped without a normal map under LEAN or Toksvig, the slope moments
/// of its height map; `None` otherwise.
fn moment_source<T>(
    aa: SpecularAa,
    bumped: bool,
    normal: Option<T>,
    height: Option<T>,
) -> Option<(T, Moments)> {
    match (normal, height) {
        (Some(n), _) if aa == SpecularAa::Lean => Some((n, Moments::Lean)),
        (None, Some(h)) if bumped && matches!(aa, SpecularAa::Lean | SpecularAa::Toksvig) => {
            Some((h, Moments::Slopes))
        }
        _ => None,
    }
}

/// Build the `kind` moment map of `map` (named `what` in errors) within what `budget` has left,
/// and charge it.
fn moment_map(
    kind: Moments,
    map: &Texture,
    budget: &mut MemoryBudget,
    what: &str,
) -> Result<MomentMap, Error> {
    let limits = budget.texture_limits();
    let (built, name) = match kind {
        Moments::Lean => (
            texel_raster::material::lean_map(map, &limits),
            "LEAN moments",
        ),
        Moments::Slopes => (
            texel_raster::material::height_moments(map, 0, &limits),
            "slope moments",
        ),
    };
    let moments = built.map_err(|source| {
        budget.restate(texel_scene::SceneError::Texture {
            name: format!("{what} ({name})"),
            path: None,
            source,
        })
    })?;
    budget.take(&format!("the {name} of {what}"), moments.pyramid_bytes())?;
    Ok(moments)
}

/// Where a material's maps are read through: a texture's own sampler where it brings one
/// ([`texel_scene::TextureSpec::sampler`]; the entries after the meshes' in
/// [`PreparedScene::samplers`]), else the mesh's.
#[derive(Clone, Copy)]
struct MapInputs<'a> {
    textures: &'a BTreeMap<String, Arc<Texture>>,
    /// The mesh's sampler.
    mesh: &'a Sampler,
    /// The textures' own samplers.
    own: &'a [Sampler],
    /// Per texture with its own sampler, its index in `own`.
    own_of: &'a BTreeMap<String, usize>,
}

impl<'a> MapInputs<'a> {
    /// Texture `name` read through its sampler.
    fn input(&self, name: &str) -> TextureInput<'a> {
        let sampler = self.own_of.get(name).and_then(|&i| self.own.get(i));
        TextureInput {
            texture: &self.textures[name],
            sampler: sampler.unwrap_or(self.mesh),
        }
    }

    /// The red channel of texture `name`.
    fn red(&self, name: &str) -> ChannelInput<'a> {
        ChannelInput {
            input: self.input(name),
            channel: 0,
        }
    }

    /// A number, or a factor times a texture's channel.
    fn scalar(&self, s: &ScalarInput) -> (f32, Option<ChannelInput<'a>>) {
        let (factor, map) = s.parts();
        let map = map.map(|(texture, channel)| ChannelInput {
            input: self.input(texture),
            channel: usize::from(channel),
        });
        (factor, map)
    }
}

/// The red channel of `texture` read through `sampler`.
fn red<'a>(texture: &'a Texture, sampler: &'a Sampler) -> ChannelInput<'a> {
    ChannelInput {
        input: TextureInput { texture, sampler },
        channel: 0,
    }
}

/// The rasterizer's layers of layered material `spec`, every input read through `maps`.
fn layers_of<'a>(
    spec: &MaterialSpec,
    maps: MapInputs<'a>,
    lean_maps: &'a BTreeMap<String, Arc<MomentMap>>,
) -> Layers<'a> {
    let input = |name: &String| maps.input(name);
    let mut layers = [Layer::default(); MAX_LAYERS];
    for (slot, l) in layers.iter_mut().zip(&spec.layers) {
        let (roughness, roughness_map) = maps.scalar(&l.roughness);
        let (height, height_map) = match &l.height {
            Some(h) => maps.scalar(h),
            None => (Layer::default().height, None),
        };
        *slot = Layer {
            base_color: match l.base_color {
                ColorInput::Rgb(c) => c.extend(1.0),
                ColorInput::Texture(_) => glam::Vec4::ONE,
            },
            base_map: match &l.base_color {
                ColorInput::Texture(t) => Some(input(t)),
                ColorInput::Rgb(_) => None,
            },
            roughness,
            roughness_map,
            normal_map: l.normal.as_ref().map(input),
            normal_scale: l.normal_scale,
            lean: l
                .normal
                .as_ref()
                .and_then(|n| lean_maps.get(n))
                .map(Arc::as_ref),
            height,
            height_map,
        };
    }
    Layers {
        mask: spec.mask.as_ref().map(input),
        layers,
        count: spec.layers.len().min(MAX_LAYERS),
        blend: match spec.blend {
            LayerBlendSpec::Linear => LayerBlend::Linear,
            LayerBlendSpec::Height => LayerBlend::Height {
                depth: spec.blend_depth,
            },
        },
        heights: spec.layer_heights(),
    }
}

/// The most triangles a tessellated mesh may have: 2^25, the scene's own default limit. The
/// reference's geometry of `builtin:bricks` at 1280 x 720 (0.75-pixel edges) has 9.3 million.
pub(crate) const MAX_TESSELLATED_TRIANGLES: usize = 1 << 25;

/// The displacement a material gets: `overridden` (the CLI's `--displacement`) or its own.
fn displacement(
    spec: &texel_scene::MaterialSpec,
    overridden: Option<texel_scene::Displacement>,
) -> texel_scene::Displacement {
    overridden.unwrap_or(spec.displacement)
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
            if let Some(t) = &mesh.tangents {
                v.tangent = t[k];
            }
            v
        })
        .collect()
}

/// A light direction as the shading normalises it: unchanged where its length squared is a normal
/// f32, else the unit vector of the same direction found in f64 (a direction of `[3e38, 3e38,
/// 3e38]` overflows f32's length and one of `1e-30` underflows it; both name a direction).
pub(crate) fn shading_direction(direction: glam::Vec3) -> glam::Vec3 {
    let l = direction.length_squared();
    if l.is_normal() && l.is_finite() {
        return direction;
    }
    direction
        .as_dvec3()
        .try_normalize()
        .map_or(direction, |d| d.as_vec3())
}

#[cfg(test)]
mod direction_tests {
    use super::shading_direction;
    use glam::Vec3;

    #[test]
    fn directions_beyond_f32_squares_keep_their_direction() {
        let d = Vec3::new(1.0, 2.0, 2.0);
        assert_eq!(shading_direction(d), d);
        let huge = shading_direction(Vec3::splat(3e38));
        let want = Vec3::splat(1.0 / 3f32.sqrt());
        assert!((huge - want).length() < 1e-6, "{huge}");
        let tiny = shading_direction(Vec3::new(0.0, 1e-30, -1e-30));
        assert!(
            (tiny - Vec3::new(0.0, 1.0, -1.0).normalize()).length() < 1e-6,
            "{tiny}"
        );
        assert!((huge.length() - 1.0).abs() < 1e-6);
    }
}

#[cfg(test)]
mod color_tests {
    use super::{ColorHandling, ColorSpace, ColorTarget};
    use texel_quality::Encoding;

    #[test]
    fn each_handling_names_one_encoding_space_and_target() {
        let srgb = ColorHandling::Srgb;
        let raw = ColorHandling::Raw;
        assert_eq!(
            (srgb.encoding(), srgb.color_space(), srgb.target()),
            (Encoding::Srgb, ColorSpace::Srgb, ColorTarget::Srgb8)
        );
        assert_eq!(
            (raw.encoding(), raw.color_space(), raw.target()),
            (Encoding::Linear, ColorSpace::Linear, ColorTarget::Unorm8)
        );
        for c in ColorHandling::ALL {
            assert_eq!(c.to_string().parse::<ColorHandling>(), Ok(c));
            assert_eq!(c.name().to_uppercase().parse::<ColorHandling>(), Ok(c));
            // The ends decode exactly; the encoding of a decoded value gives it back.
            assert_eq!((c.decode(0), c.decode(255)), (0.0, 1.0));
            for v in [1u8, 64, 128, 200, 254] {
                let l = c.decode(v);
                assert_eq!(c.encoding().encode([l, l, l, 1.0])[0], v, "{c} {v}");
            }
        }
        // sRGB's 128 is 0.2158 linear (IEC 61966-2-1), raw's is 128/255.
        assert!((srgb.decode(128) - 0.215_861).abs() < 1e-5);
        assert_eq!(raw.decode(128), 128.0 / 255.0);
        assert!("linear".parse::<ColorHandling>().is_err());
    }
}
