//! Bounds on what a scene may make texel read and allocate, checked before the allocation.

use std::path::Path;

use crate::error::SceneError;

/// How much a scene and its mesh files may hold. Checked from file sizes and headers (glTF
/// accessor counts, OBJ face lines) before anything proportional is allocated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneLimits {
    /// Largest scene TOML file, in bytes. Default 64 MiB (inline meshes of about a million
    /// triangles; larger meshes belong in OBJ or glTF files).
    pub max_scene_bytes: u64,
    /// Largest OBJ file, glTF/GLB file, and sum of one glTF's buffers (`byteLength`), in bytes.
    /// Default 512 MiB.
    pub max_mesh_file_bytes: u64,
    /// Most triangles in the whole scene (glTF instances counted once per instance).
    /// Default 2^25 = 33,554,432.
    pub max_triangles: u64,
    /// Most vertices in the whole scene (glTF instances counted once per instance).
    /// Default 2^25.
    pub max_vertices: u64,
    /// Most meshes in the whole scene: inline entries, and every instance of a glTF primitive
    /// (each is a mesh of its own, with its own copy of the vertices). Default 2^16 = 65,536.
    pub max_meshes: u64,
}

impl Default for SceneLimits {
    fn default() -> Self {
        SceneLimits {
            max_scene_bytes: 64 << 20,
            max_mesh_file_bytes: 512 << 20,
            max_triangles: 1 << 25,
            max_vertices: 1 << 25,
            max_meshes: 1 << 16,
        }
    }
}

impl SceneLimits {
    /// Read a mesh file (OBJ, glTF, GLB): a regular file of at most
    /// [`SceneLimits::max_mesh_file_bytes`] ([`texel_io::read_regular`]).
    pub(crate) fn read_mesh_file(&self, path: &Path) -> Result<Vec<u8>, SceneError> {
        texel_io::read_regular(path, self.max_mesh_file_bytes).map_err(|source| SceneError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}
