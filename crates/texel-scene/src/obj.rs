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
use crate::limits::SceneLimits;
use crate::model::Mesh;

fn chunks<const N: usize>(v: &[f32]) -> impl Iterator<Item = [f32; N]> + '_ {
    v.chunks_exact(N).map(|c| std::array::from_fn(|k| c[k]))
}

/// Load `path` as one [`Mesh`] using texture `texture` (address modes Repeat, no glTF filters),
/// within the default [`SceneLimits`].
///
/// # Errors
/// As [`load_obj_with`].
pub fn load_obj(path: &Path, texture: &str) -> Result<Mesh, SceneError> {
    load_obj_with(path, texture, &SceneLimits::default())
}

/// Load `path` as one [`Mesh`] using texture `texture`: a regular file of at most
/// [`SceneLimits::max_mesh_file_bytes`], parsed by [`load_obj_bytes`].
///
/// # Errors
/// [`SceneError::Io`] (unreadable, not a regular file, too large) and those of
/// [`load_obj_bytes`].
pub fn load_obj_with(path: &Path, texture: &str, limits: &SceneLimits) -> Result<Mesh, SceneError> {
    let bytes = limits.read_mesh_file(path)?;
    load_obj_bytes(&bytes, path, texture, limits)
}

/// What an OBJ text declares, counted before parsing: triangles (a polygon of n corners is n - 2),
/// `v` lines, and the first element line (1-based line, text) with an index out of range: one
/// reaching past the `v`, `vt` or `vn` lines above it, counting back for a negative (relative)
/// index. Such a line is an error anyway, and `tobj` computes `vt * 2 + 1` from the index before
/// checking it, which overflows. Lines are split as `tobj` splits them (Unicode whitespace), and
/// `l` and `p` lines count too: `tobj` triangulates an `l` or `p` of three or more corners like an
/// `f`.
struct Declared {
    triangles: u64,
    vertices: u64,
    bad_index: Option<(usize, String)>,
}

fn declared(text: &[u8]) -> Declared {
    let mut d = Declared {
        triangles: 0,
        vertices: 0,
        bad_index: None,
    };
    // Elements defined so far that an index may refer to: v, vt, vn.
    let mut counts = [0u64; 3];
    for (n, line) in text.split(|&b| b == b'\n').enumerate() {
        let line = String::from_utf8_lossy(line);
        let mut t = line.split_whitespace();
        match t.next() {
            Some("v") => counts[0] += 1,
            Some("vt") => counts[1] += 1,
            Some("vn") => counts[2] += 1,
            Some("f" | "l" | "p") => {
                let corners: Vec<&str> = t.collect();
                d.triangles += (corners.len() as u64).saturating_sub(2);
                let out_of_range = |c: &&str| {
                    c.split('/')
                        .zip(counts)
                        .any(|(i, count)| match i.parse::<i64>() {
                            Ok(i) => i.unsigned_abs() > count,
                            // Unparsable indices are tobj's to report; over-long numbers are out of
                            // range.
                            Err(_) => {
                                i.len() > 18 && i.bytes().all(|b| b.is_ascii_digit() || b == b'-')
                            }
                        })
                };
                if d.bad_index.is_none() && corners.iter().any(out_of_range) {
                    let shown = line.trim_end().chars().take(60).collect();
                    d.bad_index = Some((n + 1, shown));
                }
            }
            _ => {}
        }
    }
    d.vertices = counts[0];
    d
}

fn parse(text: &[u8]) -> tobj::LoadResult {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        // Triangulated, points and lines would become degenerate triangles (a, a, a) and (a, b, b).
        ignore_points: true,
        ignore_lines: true,
    };
    tobj::load_obj_buf(&mut BufReader::new(text), &opts, |_| {
        Err(tobj::LoadError::GenericFailure)
    })
}

/// The 1-based line at which parsing `text` first fails: tobj stops at the first bad line, so a
/// prefix of the file fails exactly when it contains that line (binary search over prefixes).
/// The line's text is `None` when it is not UTF-8 (binary data).
fn failing_line(text: &[u8]) -> Option<(usize, Option<String>)> {
    let ends: Vec<usize> = text
        .iter()
        .enumerate()
        .filter(|(_, &b)| b == b'\n')
        .map(|(i, _)| i + 1)
        .chain(std::iter::once(text.len()))
        .collect();
    let (mut lo, mut hi) = (0usize, ends.len() - 1);
    if parse(&text[..ends[hi]]).is_ok() {
        return None;
    }
    // Invariant: the prefix of lines 0..=hi fails; lines 0..lo (exclusive of lo) parse.
    while lo < hi {
        let mid = (lo + hi) / 2;
        if parse(&text[..ends[mid]]).is_err() {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    let start = if hi == 0 { 0 } else { ends[hi - 1] };
    let line = std::str::from_utf8(&text[start..ends[hi]]).ok().map(|l| {
        let l = l.trim_end();
        if l.chars().count() > 60 {
            l.chars().take(60).collect::<String>() + "..."
        } else {
            l.to_string()
        }
    });
    Some((hi + 1, line))
}

/// Parse OBJ text as one [`Mesh`] (module docs). `path` names the file in errors.
///
/// # Errors
/// [`SceneError::Obj`]: a parse error, with the line number and the line; [`SceneError::MeshFile`]:
/// over the limits (counted before parsing), no texture coordinates, no triangles, indices over
/// `u32`.
pub fn load_obj_bytes(
    bytes: &[u8],
    path: &Path,
    texture: &str,
    limits: &SceneLimits,
) -> Result<Mesh, SceneError> {
    let bad = |reason: String| SceneError::MeshFile {
        path: path.to_path_buf(),
        reason,
    };
    check_declared(bytes, path, limits)?;
    let models = parse_located(bytes, path)?;
    let no_triangles = || {
        bad("no triangles: an OBJ file needs f lines with 3 or more corners (points and lines are not drawn)".into())
    };
    if models.is_empty() {
        return Err(no_triangles());
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
        material: None,
        tangents: None,
        uv_mapping: None,
    };
    for model in &models {
        append_model(&mut mesh, model).map_err(bad)?;
    }
    if mesh.triangles.is_empty() {
        return Err(no_triangles());
    }
    Ok(mesh)
}

/// Checks what `bytes` declare, counted without parsing: no index out of range, and triangles
/// and vertices within `limits`.
fn check_declared(bytes: &[u8], path: &Path, limits: &SceneLimits) -> Result<(), SceneError> {
    let Declared {
        triangles: tris,
        vertices: verts,
        bad_index,
    } = declared(bytes);
    if let Some((line, text)) = bad_index {
        return Err(SceneError::Obj {
            path: path.to_path_buf(),
            at: Some(format!("line {line} ({text:?})")),
            source: tobj::LoadError::FaceVertexOutOfBounds,
        });
    }
    if tris > limits.max_triangles || verts > limits.max_vertices {
        return Err(SceneError::MeshFile {
            path: path.to_path_buf(),
            reason: format!(
                "it declares {tris} triangles and {verts} vertices, over the limits of {} triangles and {} vertices",
                limits.max_triangles, limits.max_vertices
            ),
        });
    }
    Ok(())
}

/// Parses `bytes` into `tobj`'s models; a parse error names the line it fails at.
fn parse_located(bytes: &[u8], path: &Path) -> Result<Vec<tobj::Model>, SceneError> {
    let (models, _materials) = parse(bytes).map_err(|source| SceneError::Obj {
        path: path.to_path_buf(),
        // Locating the line costs about log2(lines) more parses: done for files up to 64 MiB.
        at: (bytes.len() <= 64 << 20)
            .then(|| failing_line(bytes))
            .flatten()
            .map(|(line, text)| match text {
                Some(t) => format!("line {line} ({t:?})"),
                None => format!("line {line} (not UTF-8 text: is this an OBJ file?)"),
            }),
        source,
    })?;
    Ok(models)
}

/// Appends `model`'s vertices and triangles to `mesh` (uvs flipped to top-down); drops `mesh`'s
/// normals or colours where the model lacks them.
fn append_model(mesh: &mut Mesh, model: &tobj::Model) -> Result<(), String> {
    let m = &model.mesh;
    let n = m.positions.len() / 3;
    if m.texcoords.len() != 2 * n {
        return Err(format!(
            "object {:?} has no texture coordinates (vt) for every vertex: texel needs uvs",
            model.name
        ));
    }
    let base = u32::try_from(mesh.positions.len())
        .ok()
        .filter(|b| u64::from(*b) + n as u64 <= u64::from(u32::MAX))
        .ok_or_else(|| "more than 2^32 vertices".to_string())?;
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
    Ok(())
}
