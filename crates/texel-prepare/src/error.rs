//! The one error type of texel-prepare (and of the `texel` facade, which re-exports it): the
//! libraries' errors, plus what scene preparation adds.

use thiserror::Error;

/// Everything that can go wrong preparing or rendering a scene.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// Loading or validating the scene, its mesh files or its textures.
    #[error(transparent)]
    Scene(#[from] texel_scene::SceneError),
    /// A sampler descriptor, or building a ripmap or summed-area table.
    #[error(transparent)]
    Texture(#[from] texel_texture::TextureError),
    /// Rendering.
    #[error(transparent)]
    Raster(#[from] texel_raster::RasterError),
    /// Turning a frame into an image, or scoring one.
    #[error(transparent)]
    Quality(#[from] texel_quality::QualityError),
    /// An allocation the memory budget cannot hold ([`crate::MemoryBudget::take`], or a texture's
    /// own refusal restated by [`crate::MemoryBudget::restate`]): its bytes, and with what is
    /// already held their sum, rounded up (a limit of the sum gets past this step).
    #[error(
        "{what} needs about {}{}, over {limit}: raise the limit or make the input smaller",
        crate::memory::mib_up(*bytes),
        crate::memory::held(*used, *bytes)
    )]
    OverBudget {
        /// What was to be allocated.
        what: String,
        /// Its bytes.
        bytes: u64,
        /// Bytes already accounted for.
        used: u64,
        /// The limit, as its owner describes it (e.g. `--max-memory 512.0 MiB`).
        limit: String,
    },
    /// Ambient occlusion bake settings out of range, or a mesh it cannot bake.
    #[error("cannot bake ambient occlusion: {0}")]
    Bake(String),
    /// A comparison that cannot be scored: the frame is smaller than SSIM's window, the scene
    /// covers no pixel where it fits, or an extra image cannot be read or has another size.
    #[error("{0}")]
    Compare(String),
    /// The work was cancelled (a signal, or the caller's flag).
    #[error("cancelled")]
    Cancelled,
}
