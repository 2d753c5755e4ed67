//! The one error type of texel-scene.

use std::path::PathBuf;

use texel_texture::TextureError;
use thiserror::Error;

/// Everything that can go wrong when loading or validating a scene or building its textures.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SceneError {
    /// A file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The TOML is malformed, has an unknown key, a missing key or a value of the wrong type.
    #[error("{}{}: {message}", path.display(), position(*line, *column))]
    Toml {
        /// The scene file (`builtin:NAME` for built-in scenes).
        path: PathBuf,
        /// 1-based line of the offending text (0 when the parser gives no position).
        line: usize,
        /// 1-based column (in characters) of the offending text (0 when unknown).
        column: usize,
        /// The parser's message.
        message: String,
    },
    /// `builtin:NAME` with a name that does not exist.
    #[error("unknown built-in scene {name:?}: available are {available}")]
    UnknownBuiltin {
        /// The name after `builtin:`.
        name: String,
        /// The built-in scenes' names, unlit then lit, comma-separated.
        available: String,
    },
    /// Output size outside `1..=MAX_OUTPUT_SIDE` per side.
    #[error("output size {width}x{height} is invalid: each side must be between 1 and {max}")]
    OutputSize {
        /// Requested width in pixels.
        width: u32,
        /// Requested height in pixels.
        height: u32,
        /// The limit per side.
        max: u32,
    },
    /// A NaN or infinite number where a finite one is required.
    #[error("{what} = {value}: must be finite")]
    NonFinite {
        /// Where (e.g. `meshes[0].positions[3]`, `camera.eye`).
        what: String,
        /// The offending value, formatted.
        value: String,
    },
    /// `near` must be > 0 and `far` > `near`.
    #[error("camera near = {near}, far = {far}: need 0 < near < far")]
    CameraNearFar {
        /// Near plane distance.
        near: f32,
        /// Far plane distance.
        far: f32,
    },
    /// `fovy_deg` outside `[MIN_FOVY_DEG, 180)`.
    #[error("camera fovy_deg = {0}: must be at least {min} degrees (f32 view coordinates do not resolve a narrower view) and below 180", min = crate::camera::MIN_FOVY_DEG)]
    CameraFov(f32),
    /// `eye == target`, or `up` parallel to the view direction (or zero).
    #[error("camera eye {eye:?}, target {target:?}, up {up:?} do not define a view: eye must differ from target and up must not be parallel to the view direction")]
    CameraDegenerate {
        /// Eye position.
        eye: [f32; 3],
        /// Target position.
        target: [f32; 3],
        /// Up vector.
        up: [f32; 3],
    },
    /// A mesh names a texture that is not defined under `[textures]`.
    #[error("meshes[{mesh}] uses texture {name:?}, which is not defined (defined: {defined})")]
    UnknownTexture {
        /// Mesh index.
        mesh: usize,
        /// The missing name.
        name: String,
        /// The defined names, comma-separated.
        defined: String,
    },
    /// A mesh entry gives no geometry source, several, or inline data beside a file.
    #[error("meshes[{mesh}]: {reason}")]
    MeshSource {
        /// Mesh index.
        mesh: usize,
        /// What is wrong.
        reason: &'static str,
    },
    /// A mesh's sphere mapping (`sphere_uv` and its keys) is invalid.
    #[error("meshes[{mesh}]: {reason}")]
    MeshMapping {
        /// Mesh index.
        mesh: usize,
        /// What is wrong.
        reason: String,
    },
    /// A mesh's texture or material is missing or contradicts itself.
    #[error("meshes[{mesh}]: {reason}")]
    MeshMaterial {
        /// Mesh index.
        mesh: usize,
        /// What is wrong.
        reason: String,
    },
    /// A material is invalid.
    #[error("materials.{name}: {reason}")]
    Material {
        /// The material's name.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// The `[environment]` table is invalid.
    #[error("environment: {0}")]
    Environment(String),
    /// A light is invalid, or there are too many.
    #[error("lights: {0}")]
    Light(String),
    /// A per-vertex attribute has a different length from `positions`.
    #[error("meshes[{mesh}]: {attribute} has {got} entries but positions has {expected}")]
    MeshLength {
        /// Mesh index.
        mesh: usize,
        /// The attribute (`uvs`, `normals`, `colors`).
        attribute: &'static str,
        /// Number of positions.
        expected: usize,
        /// Entries given.
        got: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("meshes[{mesh}].triangles[{triangle}] uses vertex index {index}, but the mesh has only {vertices} vertices")]
    IndexOutOfRange {
        /// Mesh index.
        mesh: usize,
        /// Triangle index.
        triangle: usize,
        /// The offending vertex index.
        index: u32,
        /// Number of vertices.
        vertices: usize,
    },
    /// A texture entry is inconsistent: neither or both of `path` and `procedural`, a parameter the
    /// kind does not take, a zero count, ...
    #[error("textures.{name}: {reason}")]
    InvalidTexture {
        /// Texture name.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// A texture could not be created (size or memory limits) or its file not read or decoded.
    #[error("textures.{name}{}: {source}", path.as_ref().map(|p| format!(" ({})", p.display())).unwrap_or_default())]
    Texture {
        /// Texture name.
        name: String,
        /// The image file, for file textures.
        path: Option<PathBuf>,
        /// The underlying error.
        source: TextureError,
    },
    /// An OBJ file could not be parsed.
    #[error("{path}: cannot load OBJ: {}{source}", at.as_ref().map(|a| format!("{a}: ")).unwrap_or_default())]
    Obj {
        /// The OBJ file.
        path: PathBuf,
        /// Where parsing failed: `line N ("text")`, when it could be found.
        at: Option<String>,
        /// The parser's error.
        source: tobj::LoadError,
    },
    /// A glTF file could not be parsed, or its buffers not loaded.
    #[error("{path}: cannot load glTF: {source}")]
    Gltf {
        /// The glTF file.
        path: PathBuf,
        /// The parser's error.
        source: gltf::Error,
    },
    /// A mesh file is readable but unusable: no texture coordinates, an accessor outside its buffer,
    /// a primitive mode that is not made of triangles, ...
    #[error("{path}: {reason}")]
    MeshFile {
        /// The mesh file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The scene is larger than its [`crate::SceneLimits`] allow.
    #[error("{0}")]
    TooLarge(String),
    /// The scene draws nothing: no meshes, or a mesh without triangles.
    #[error("{0}")]
    Empty(String),
}

/// `:LINE:COLUMN` for a known position, nothing for an unknown one (line 0).
fn position(line: usize, column: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!(":{line}:{column}")
    }
}
