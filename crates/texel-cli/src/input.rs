//! Loading a scene for a command: [`texel::PreparedScene`] with the command line's memory account,
//! `--sanitize` policy and error wording.

use anyhow::Result;
use texel::texture::{Limits, LoadOptions, TextureError};
use texel::{MemoryBudget, PreparedScene, Scene, SceneLimits, SceneOptions, TextureStorage};

use texel::raster::SpecularAa;

use crate::cli::{SceneArgs, Size};

/// How a command reads its inputs: the memory account and the policy for non-finite and
/// out-of-range texels.
pub(crate) struct Input {
    /// The `--max-memory` account.
    pub budget: MemoryBudget,
    /// `--sanitize`: replace NaN, infinite and out-of-range texels instead of refusing them.
    pub sanitize: bool,
}

impl Input {
    /// How a command-line image is read: `color` for 8-bit data, `--sanitize`, and a memory limit
    /// of what the account has left.
    pub(crate) fn texture_options(&self, color: texel::ColorHandling) -> LoadOptions {
        let color = color.color_space();
        LoadOptions {
            replace_non_finite: self.sanitize,
            ..LoadOptions::new(
                color,
                Limits {
                    max_bytes: self.budget.remaining(),
                    ..Limits::default()
                },
            )
        }
    }

    /// Print a warning when `--sanitize` replaced values of texture `name`.
    pub(crate) fn warn_replaced(&self, name: &str, replaced: u64) {
        if replaced > 0 {
            texel_io::stderr_line(format_args!(
                "texel: warning: texture {name:?}: replaced {replaced} NaN, infinite or out-of-range channel values (NaN -> 0, +-inf -> +-{inf}, beyond +-{max:e} -> +-{max:e})",
                inf = texel::texture::NON_FINITE_CLAMP,
                max = texel::texture::MAX_TEXEL
            ));
        }
    }

    /// Add to a texture's memory-limit error which flag sets the limit.
    pub(crate) fn explain(&self, e: anyhow::Error) -> anyhow::Error {
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
                self.budget.name()
            ))
        } else {
            e
        }
    }
}

/// Load the scene of a command's [`SceneArgs`] within `input`'s account.
pub(crate) fn load_scene(args: &SceneArgs, input: &mut Input) -> Result<PreparedScene> {
    load_scene_with(
        &args.scene,
        args.color,
        args.size,
        MaterialOverrides::of(args),
        input,
    )
}

/// What the CLI overrides in every material (`--specular-aa`, `--displacement`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct MaterialOverrides {
    /// `--specular-aa`.
    pub specular_aa: Option<SpecularAa>,
    /// `--shading-samples`.
    pub shading_samples: Option<u32>,
    /// `--displacement`.
    pub displacement: Option<texel::scene::Displacement>,
    /// `--edge-px`.
    pub edge_px: Option<f32>,
    /// `--layer-order`.
    pub layer_order: Option<texel::scene::LayerOrder>,
    /// `--environment-mapping`.
    pub environment_mapping: Option<texel::scene::Mapping>,
    /// `--surface-uv`.
    pub surface_uv: Option<texel::raster::UvEvaluation>,
    /// `--precision`.
    pub precision: texel::raster::Precision,
    /// `--texture-storage`, or the command's default.
    pub texture_storage: TextureStorage,
    /// `--convention`.
    pub convention: texel::texture::Convention,
}

impl MaterialOverrides {
    /// The overrides a command's [`SceneArgs`] give.
    pub(crate) fn of(args: &SceneArgs) -> Self {
        MaterialOverrides {
            specular_aa: args.specular_aa,
            shading_samples: args.shading_samples,
            displacement: args.displacement,
            edge_px: args.edge_px,
            layer_order: args.layer_order,
            environment_mapping: args.environment_mapping,
            surface_uv: args.surface_uv,
            precision: args.precision,
            texture_storage: args.texture_storage.unwrap_or_default(),
            convention: args.convention,
        }
    }
}

/// The texture storage a command with `args` and `gpu` (its `--gpu`) runs with:
/// `--texture-storage` when given, else `preferred`. The GPU path uploads the texels as stored
/// and the fixed-point path (`--precision gpu`) reads 8-bit codes, so with either `float` is
/// refused when asked for and not chosen by default.
pub(crate) fn texture_storage(
    args: &SceneArgs,
    gpu: bool,
    preferred: TextureStorage,
) -> Result<TextureStorage> {
    let stored_only = if gpu {
        Some("--texture-storage float is for the CPU's filters; --gpu uploads the texels as stored")
    } else if args.precision == texel::raster::Precision::Gpu {
        Some(
            "--texture-storage float and --precision gpu: the fixed-point filters read 8-bit codes",
        )
    } else {
        None
    };
    Ok(match (args.texture_storage, stored_only) {
        (Some(TextureStorage::Float), Some(why)) => anyhow::bail!("{why}"),
        (Some(asked), _) => asked,
        (None, Some(_)) => TextureStorage::Stored,
        (None, None) => preferred,
    })
}

/// [`texture_storage`]'s refusals for a command whose default is stored.
pub(crate) fn check_storage(args: &SceneArgs, gpu: bool) -> Result<()> {
    texture_storage(args, gpu, TextureStorage::Stored).map(drop)
}

/// Load `scene` (a path or `builtin:NAME`) and its textures within `input`'s account, with
/// `color` handling, an output `size` and the material `overrides`.
pub(crate) fn load_scene_with(
    scene: &str,
    color: texel::ColorHandling,
    size: Option<Size>,
    overrides: MaterialOverrides,
    input: &mut Input,
) -> Result<PreparedScene> {
    let limits = input.budget.scene_limits();
    let d = SceneLimits::default();
    // The limits lowered to fit the account, as the errors print them.
    let lowered: Vec<String> = [
        (limits.max_scene_bytes, d.max_scene_bytes),
        (limits.max_mesh_file_bytes, d.max_mesh_file_bytes),
        (limits.max_triangles, d.max_triangles),
        (limits.max_vertices, d.max_vertices),
    ]
    .iter()
    .filter(|(l, d)| l < d)
    .map(|(l, _)| l.to_string())
    .collect();
    let loaded = Scene::load_with(scene, &limits).map_err(|e| {
        // A size limit lowered to fit the account says so; a limit at its default does not.
        let text = e.to_string();
        let note = if lowered.iter().any(|l| text.contains(l.as_str())) {
            format!(
                " (its size limits are scaled down to fit {})",
                input.budget.name()
            )
        } else {
            String::new()
        };
        anyhow::Error::new(e).context(format!("cannot load scene {scene}{note}"))
    })?;
    let options = SceneOptions {
        size: size.map(|s| (s.width, s.height)),
        color,
        replace_non_finite: input.sanitize,
        specular_aa: overrides.specular_aa,
        shading_samples: overrides.shading_samples,
        displacement: overrides.displacement,
        edge_px: overrides.edge_px,
        layer_order: overrides.layer_order,
        environment_mapping: overrides.environment_mapping,
        surface_uv: overrides.surface_uv.unwrap_or_default(),
        precision: overrides.precision,
        texture_storage: overrides.texture_storage,
        convention: overrides.convention,
    };
    let prepared = PreparedScene::new(loaded, &options, &mut input.budget)
        .map_err(|e| input.explain(e.into()))?;
    for (name, n) in &prepared.replaced {
        input.warn_replaced(name, *n);
    }
    for (name, bytes) in &prepared.kept_stored {
        texel_io::stderr_line(format_args!(
            "texel: note: texture {name:?} stays 8-bit: its float copy ({}) does not fit {}",
            texel::memory::mib(*bytes),
            input.budget.name()
        ));
    }
    Ok(prepared)
}
