//! Wavefront OBJ meshes through `tobj`: triangulated, one index per vertex.
//!
//! Every object and group of the file is merged into one mesh. Texture coordinates are required;
//! OBJ's `v` runs bottom-up (OpenGL), so it is flipped (`v' = 1 - v`) to texel's top-down
//! convention. Normals and vertex colours (the `v x y z r g b` extension) are kept when every
//! object has them. Materials (`mtllib`) are ignored: the scene file names the texture.

use std::io::BufReader;
use std::path::Path;

use glam::{Vec2, Vec3, Vec4};
use texel_texture::AddressMode;

use crate::error::SceneError;
use crate::model::Mesh;

fn chunks<const N: usize>(v: &[f32]) -> impl Iterator<Item = [f32; N]> + '_ {
    v.chunks_exact(N).map(|c| std::array::from_fn(|k| c[k]))
}

/// Load `path` as one [`Mesh`] using texture `texture` (address modes Repeat, no glTF filters).
///
/// # Errors
/// [`SceneError::Io`] (unreadable), [`SceneError::Obj`] (parse error),
/// [`SceneError::MeshFile`] (no texture coordinates, indices over `u32`).
pub fn load_obj(path: &Path, texture: &str) -> Result<Mesh, SceneError> {
    let file = std::fs::File::open(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _materials) = tobj::load_obj_buf(&mut BufReader::new(file), &opts, |_| {
        Err(tobj::LoadError::GenericFailure)
    })
    .map_err(|source| SceneError::Obj {
        path: path.to_path_buf(),
        source,
    })?;
    let bad = |reason: String| SceneError::MeshFile {
        path: path.to_path_buf(),
        reason,
    };
    if models.is_empty() {
        return Err(bad("the OBJ file has no faces".into()));
    }
    let mut mesh = Mesh {
        positions: Vec::new(),
        uvs: Vec::new(),
        normals: Some(Vec::new()),
        colors: Some(Vec::new()),
        triangles: Vec::new(),
        texture: texture.to_string(),
        address_mode_u: AddressMode::Repeat,
        address_mode_v: AddressMode::Repeat,
        filters: None,
    };
    for model in &models {
        let m = &model.mesh;
        let n = m.positions.len() / 3;
        if m.texcoords.len() != 2 * n {
            return Err(bad(format!(
                "object {:?} has no texture coordinates (vt) for every vertex: texel needs uvs",
                model.name
            )));
        }
        let base = u32::try_from(mesh.positions.len())
            .ok()
            .filter(|b| u64::from(*b) + n as u64 <= u64::from(u32::MAX))
            .ok_or_else(|| bad("more than 2^32 vertices".into()))?;
        mesh.positions
            .extend(chunks::<3>(&m.positions).map(Vec3::from));
        mesh.uvs
            .extend(chunks::<2>(&m.texcoords).map(|[u, v]| Vec2::new(u, 1.0 - v)));
        if m.normals.len() == 3 * n {
            if let Some(ns) = &mut mesh.normals {
                ns.extend(chunks::<3>(&m.normals).map(Vec3::from));
            }
        } else {
            mesh.normals = None;
        }
        if m.vertex_color.len() == 3 * n {
            if let Some(cs) = &mut mesh.colors {
                cs.extend(chunks::<3>(&m.vertex_color).map(|[r, g, b]| Vec4::new(r, g, b, 1.0)));
            }
        } else {
            mesh.colors = None;
        }
        mesh.triangles.extend(
            m.indices
                .chunks_exact(3)
                .map(|t| [base + t[0], base + t[1], base + t[2]]),
        );
    }
    Ok(mesh)
}
