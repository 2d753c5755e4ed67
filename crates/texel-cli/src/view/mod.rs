//! `texel view`: the flags parsed, the scene loaded, then [`texel_view::run`] opens the window.

use anyhow::{anyhow, Result};
use texel::{ColorHandling, MemoryBudget, PreparedScene, TextureStorage};
use texel_gpu::Gpu;

use crate::cli::{Size, ViewArgs};
use crate::input::{load_scene_with, texture_storage, Input, MaterialOverrides};

/// The scene argument loaded as `texel view` loads it, for either colour handling, within the
/// command's account.
struct CliScene {
    /// A path or `builtin:NAME`.
    spec: String,
    /// `--size`.
    size: Option<Size>,
    /// The material and sampling flags.
    overrides: MaterialOverrides,
    /// The memory account and input policy.
    input: Input,
}

impl texel_view::SceneSource for CliScene {
    fn load(&mut self, color: ColorHandling) -> Result<PreparedScene> {
        load_scene_with(
            &self.spec,
            color,
            self.size,
            self.overrides,
            &mut self.input,
        )
    }

    fn budget(&mut self) -> &mut MemoryBudget {
        &mut self.input.budget
    }
}

/// Run `texel view`.
pub(crate) fn run(args: &ViewArgs, input: Input) -> Result<()> {
    let presses = texel_view::parse_keys(args.keys.as_deref().unwrap_or(""))
        .map_err(|e| anyhow!("--keys: {e}"))?;
    // The window's textures are decoded to float by default where its filters run on the CPU
    // (the same images, anisotropic frames faster; docs/decisions.md).
    let overrides = MaterialOverrides {
        texture_storage: texture_storage(&args.scene, args.gpu, TextureStorage::Float)?,
        ..MaterialOverrides::of(&args.scene)
    };
    let a = &args.scene;
    let mut source = CliScene {
        spec: a.scene.clone(),
        size: a.size,
        overrides,
        input,
    };
    let scene = load_scene_with(&a.scene, a.color, a.size, overrides, &mut source.input)?;
    let gpu = if args.gpu {
        Some(Gpu::new(args.adapter.as_deref())?)
    } else {
        None
    };
    texel_view::run(texel_view::Viewer {
        title: format!("texel view - {}", a.scene),
        scene,
        color: a.color,
        source: Box::new(source),
        threads: args.threads,
        gpu,
        shader: args.shader.clone(),
        frames: args.frames.map(u64::from),
        screenshot: args.screenshot.clone(),
        save: crate::output::write_image,
        presses,
        hud: args.hud,
    })
}
