//! Loading a scene for a command: [`texel::PreparedScene`] with the command line's memory account,
//! `--sanitize` policy and error wording.

use anyhow::{Context, Result};
use texel::{MemoryBudget, PreparedScene, Scene, SceneLimits, SceneOptions};
use texel_texture::TextureError;

use crate::cli::{ColorArg, Size};

/// How a command reads its inputs: the memory account and the non-finite-texel policy.
pub struct Input {
    /// The `--max-memory` account.
    pub budget: MemoryBudget,
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
                self.budget.name()
            ))
        } else {
            e
        }
    }
}

/// Load `scene` (a path or `builtin:NAME`) and its textures within `input`'s account.
pub fn load_scene(
    scene: &str,
    color: ColorArg,
    size: Option<Size>,
    input: &mut Input,
) -> Result<PreparedScene> {
    let loaded = Scene::load_with(scene, &SceneLimits::default())
        .with_context(|| format!("cannot load scene {scene}"))?;
    let options = SceneOptions {
        size: size.map(|s| (s.width, s.height)),
        color: color.into(),
        replace_non_finite: input.sanitize,
    };
    let prepared = PreparedScene::new(loaded, &options, &mut input.budget)
        .map_err(|e| input.explain(e.into()))?;
    for (name, n) in &prepared.replaced {
        input.warn_replaced(name, *n);
    }
    Ok(prepared)
}
