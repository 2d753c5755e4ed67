//! The one error type of texel-shade.

use thiserror::Error;

/// What can go wrong building shading inputs (environment maps and their prefiltered levels).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ShadeError {
    /// An environment map's faces do not fit its mapping (six square faces of one size for a
    /// cube, one square image for an octahedral map).
    #[error("environment map: {0}")]
    InvalidEnvironment(&'static str),
    /// A texture could not be created (a prefiltered level over its limits).
    #[error(transparent)]
    Texture(#[from] texel_texture::TextureError),
}
