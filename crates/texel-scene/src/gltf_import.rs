//! glTF 2.0 meshes (`.gltf` with embedded or external buffers, or binary `.glb`) through the
//! `gltf` crate.
//!
//! The default scene (else the first; else every mesh untransformed) is walked from its root nodes;
//! each node's local transform is composed with its parent's, and every primitive becomes one
//! [`Mesh`] with world-space positions (normals by the inverse transpose, renormalised).
//! `POSITION` and `TEXCOORD_0` are required; `NORMAL` and `COLOR_0` are kept when present; without
//! `indices` the vertices are taken in order. `TRIANGLES`, `TRIANGLE_STRIP` and `TRIANGLE_FAN`
//! are turned into triangle lists (glTF 2.0 spec 3.7.2.1); points and lines are an error.
//!
//! The base colour texture's sampler gives the address modes (`wrapS`/`wrapT`: `REPEAT` ->
//! Repeat, `MIRRORED_REPEAT` -> MirrorRepeat, `CLAMP_TO_EDGE` -> ClampToEdge; glTF's default is
//! Repeat) and the filters ([`MeshFilters`]). Images are not loaded: the scene file names the
//! texture. Buffers are loaded with `gltf::import_buffers` (data URIs, files beside the glTF, the
//! GLB binary chunk); accessors outside their buffers read as missing and are reported.

use std::path::Path;

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use gltf::mesh::Mode;
use gltf::texture::{MagFilter, MinFilter, WrappingMode};
use texel_texture::{AddressMode, FilterMode, MipmapFilterMode};

use crate::error::SceneError;
use crate::model::{Mesh, MeshFilters};

fn wrap(m: WrappingMode) -> AddressMode {
    match m {
        WrappingMode::ClampToEdge => AddressMode::ClampToEdge,
        WrappingMode::MirroredRepeat => AddressMode::MirrorRepeat,
        WrappingMode::Repeat => AddressMode::Repeat,
    }
}

/// The [`MeshFilters`] for a glTF sampler's `magFilter` and `minFilter`.
pub fn filters(mag: Option<MagFilter>, min: Option<MinFilter>) -> MeshFilters {
    use FilterMode::{Linear, Nearest};
    let (min_filter, mipmap_filter) = match min {
        None => (None, None),
        Some(MinFilter::Nearest) => (Some(Nearest), Some(MipmapFilterMode::None)),
        Some(MinFilter::Linear) => (Some(Linear), Some(MipmapFilterMode::None)),
        Some(MinFilter::NearestMipmapNearest) => (Some(Nearest), Some(MipmapFilterMode::Nearest)),
        Some(MinFilter::LinearMipmapNearest) => (Some(Linear), Some(MipmapFilterMode::Nearest)),
        Some(MinFilter::NearestMipmapLinear) => (Some(Nearest), Some(MipmapFilterMode::Linear)),
        Some(MinFilter::LinearMipmapLinear) => (Some(Linear), Some(MipmapFilterMode::Linear)),
    };
    MeshFilters {
        mag_filter: mag.map(|m| match m {
            MagFilter::Nearest => Nearest,
            MagFilter::Linear => Linear,
        }),
        min_filter,
        mipmap_filter,
    }
}

/// Deepest node nesting followed (guards against cyclic hierarchies in malformed files).
const MAX_DEPTH: usize = 256;

struct Ctx<'a> {
    path: &'a Path,
    texture: &'a str,
    buffers: &'a [gltf::buffer::Data],
    out: Vec<Mesh>,
}

impl Ctx<'_> {
    fn bad(&self, reason: String) -> SceneError {
        SceneError::MeshFile {
            path: self.path.to_path_buf(),
            reason,
        }
    }

    fn node(&mut self, node: gltf::Node, parent: Mat4, depth: usize) -> Result<(), SceneError> {
        if depth > MAX_DEPTH {
            return Err(self.bad(format!(
                "node hierarchy deeper than {MAX_DEPTH} (a cycle?) at node {}",
                node.index()
            )));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            self.mesh(&mesh, world)?;
        }
        for child in node.children() {
            self.node(child, world, depth + 1)?;
        }
        Ok(())
    }

    fn mesh(&mut self, mesh: &gltf::Mesh, world: Mat4) -> Result<(), SceneError> {
        let normal_from_world = Mat3::from_mat4(world).inverse().transpose();
        for (pi, prim) in mesh.primitives().enumerate() {
            let what = format!("mesh {} primitive {pi}", mesh.index());
            let buffers = self.buffers;
            let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let positions: Vec<Vec3> = reader
                .read_positions()
                .ok_or_else(|| self.bad(format!("{what}: no readable POSITION")))?
                .map(|p| world.transform_point3(Vec3::from(p)))
                .collect();
            let uvs: Vec<Vec2> = reader
                .read_tex_coords(0)
                .ok_or_else(|| {
                    self.bad(format!("{what}: no readable TEXCOORD_0 (texel needs uvs)"))
                })?
                .into_f32()
                .map(Vec2::from)
                .collect();
            let normals = reader.read_normals().map(|it| {
                it.map(|n| (normal_from_world * Vec3::from(n)).normalize_or_zero())
                    .collect::<Vec<_>>()
            });
            let colors = reader
                .read_colors(0)
                .map(|c| c.into_rgba_f32().map(Vec4::from).collect::<Vec<_>>());
            let n = positions.len() as u32;
            let indices: Vec<u32> = match prim.indices() {
                Some(_) => reader
                    .read_indices()
                    .ok_or_else(|| self.bad(format!("{what}: indices outside their buffer")))?
                    .into_u32()
                    .collect(),
                None => (0..n).collect(),
            };
            let triangles: Vec<[u32; 3]> = match prim.mode() {
                Mode::Triangles => indices
                    .chunks_exact(3)
                    .map(|t| [t[0], t[1], t[2]])
                    .collect(),
                Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
                    .map(|i| {
                        if i % 2 == 0 {
                            [indices[i], indices[i + 1], indices[i + 2]]
                        } else {
                            [indices[i + 1], indices[i], indices[i + 2]]
                        }
                    })
                    .collect(),
                Mode::TriangleFan => (1..indices.len().saturating_sub(1))
                    .map(|i| [indices[0], indices[i], indices[i + 1]])
                    .collect(),
                other => {
                    return Err(self.bad(format!(
                        "{what}: mode {other:?} has no triangles to texture"
                    )))
                }
            };
            let sampler = prim
                .material()
                .pbr_metallic_roughness()
                .base_color_texture()
                .map(|info| info.texture().sampler());
            let (address_mode_u, address_mode_v, filters) = match &sampler {
                Some(s) => (
                    wrap(s.wrap_s()),
                    wrap(s.wrap_t()),
                    Some(filters(s.mag_filter(), s.min_filter())),
                ),
                None => (AddressMode::Repeat, AddressMode::Repeat, None),
            };
            self.out.push(Mesh {
                positions,
                uvs,
                normals,
                colors,
                triangles,
                texture: self.texture.to_string(),
                address_mode_u,
                address_mode_v,
                filters,
            });
        }
        Ok(())
    }
}

/// Load every triangle primitive of `path` (module docs) as meshes using texture `texture`.
///
/// # Errors
/// [`SceneError::Io`] (unreadable file), [`SceneError::Gltf`] (malformed glTF/GLB, missing or short
/// buffer), [`SceneError::MeshFile`] (no positions or uvs, non-triangle primitives, no meshes).
pub fn load_gltf(path: &Path, texture: &str) -> Result<Vec<Mesh>, SceneError> {
    let bytes = std::fs::read(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let gerr = |source| SceneError::Gltf {
        path: path.to_path_buf(),
        source,
    };
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice(&bytes).map_err(gerr)?;
    let base = path.parent().unwrap_or(Path::new("."));
    let buffers = gltf::import_buffers(&document, Some(base), blob).map_err(gerr)?;
    let mut ctx = Ctx {
        path,
        texture,
        buffers: &buffers,
        out: Vec::new(),
    };
    match document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        Some(scene) => {
            for node in scene.nodes() {
                ctx.node(node, Mat4::IDENTITY, 0)?;
            }
        }
        None => {
            for mesh in document.meshes() {
                ctx.mesh(&mesh, Mat4::IDENTITY)?;
            }
        }
    }
    if ctx.out.is_empty() {
        return Err(ctx.bad("no mesh primitives in the file's scene".into()));
    }
    Ok(ctx.out)
}
