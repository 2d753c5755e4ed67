//! True displacement: screen-space adaptive tessellation of a mesh and displacement of its
//! vertices by a height map (`displacement = "tessellate"`, and the reference's geometry for every
//! displaced material).
//!
//! Tessellation splits every edge whose projection is longer than a target length in pixels at
//! its midpoint, recursively, a triangle with one, two or three long edges becoming two, three or
//! four. Whether an edge splits depends on its two end points only, and a midpoint is made once
//! per edge, so neighbouring triangles agree and the mesh stays watertight (no T-junctions), as
//! the rasterizer's shared-vertex rule needs. An edge that crosses the near plane is measured by
//! its part in front of it (edges wholly behind are not split), and triangles wholly outside one
//! plane of the view frustum are kept as they are.
//!
//! Displacement moves each vertex along its unit normal to `p + height_scale (h - 1) n` (the mesh
//! is the top of the relief, [`texel_raster::Displacement`]). pbrt-v4 reads `h` from level 0 at
//! the vertex, which aliases when the triangles are larger than a texel; here `h` is read through
//! a trilinear footprint as wide (in texture coordinates) as the vertex's longest edge, the
//! height filtered to the sampling rate the mesh gives it. The reference's geometry is
//! tessellated to a fraction of a pixel and reads level 0.

use std::collections::HashMap;

use glam::{Mat4, Vec2, Vec4};
use texel_raster::Vertex;
use texel_texture::{AddressMode, Filter, Footprint, Sampler, SamplerDescriptor, Texture};

/// A tessellated mesh: vertices (the original ones first) and triangles.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tessellated {
    /// Vertices, world space.
    pub vertices: Vec<Vertex>,
    /// Counter-clockwise triangles, as the mesh's.
    pub triangles: Vec<[u32; 3]>,
}

/// Where and how finely to tessellate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tessellation {
    /// The camera: world to clip space.
    pub clip_from_world: Mat4,
    /// The viewport in pixels.
    pub width: u32,
    /// The viewport in pixels.
    pub height: u32,
    /// The longest projected edge kept, pixels (`> 0`).
    pub edge_px: f32,
    /// The most triangles the result may have.
    pub max_triangles: usize,
}

/// The edge length, in pixels, that `displacement = "tessellate"` tessellates to.
pub const RENDER_EDGE_PX: f32 = 4.0;

/// The edge length, in pixels, of the reference's displaced geometry.
pub const REFERENCE_EDGE_PX: f32 = 0.75;

/// Tessellation that would pass [`Tessellation::max_triangles`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("tessellating to the edge length asked makes over {max} triangles")]
pub struct TooManyTriangles {
    /// The limit.
    pub max: usize,
}

impl Tessellation {
    /// The projected length, pixels, of the part of clip-space segment `a`-`b` in front of the
    /// near plane (`z >= -w`); `None` where all of it is behind. A segment that crosses the near
    /// plane is measured from its visible end to where it crosses (an edge with an end behind
    /// the eye is still split where its visible part is long).
    fn visible_length(&self, a: Vec4, b: Vec4) -> Option<f32> {
        let (da, db) = (a.z + a.w, b.z + b.w);
        let (a, b) = match (da >= 0.0, db >= 0.0) {
            (true, true) => (a, b),
            (false, false) => return None,
            (true, false) => (a, a + (b - a) * (da / (da - db))),
            (false, true) => (b + (a - b) * (db / (db - da)), b),
        };
        Some(self.pixel(a)?.distance(self.pixel(b)?))
    }

    /// The pixel position of a clip-space point in front of the eye.
    fn pixel(&self, c: Vec4) -> Option<Vec2> {
        (c.w > 1e-6).then(|| {
            Vec2::new(
                (c.x / c.w + 1.0) * 0.5 * self.width as f32,
                (1.0 - c.y / c.w) * 0.5 * self.height as f32,
            )
        })
    }
}

/// The vertex halfway between `a` and `b` (every attribute averaged; the tangent's handedness
/// is `a`'s).
fn midpoint(a: &Vertex, b: &Vertex) -> Vertex {
    Vertex {
        position: (a.position + b.position) * 0.5,
        uv: (a.uv + b.uv) * 0.5,
        color: (a.color + b.color) * 0.5,
        normal: (a.normal + b.normal) * 0.5,
        tangent: ((a.tangent + b.tangent) * 0.5)
            .truncate()
            .extend(a.tangent.w),
    }
}

/// Whether the clip-space triangle lies wholly outside one plane of the frustum.
fn outside(c: [Vec4; 3]) -> bool {
    let all = |f: &dyn Fn(Vec4) -> bool| c.iter().all(|&p| f(p));
    all(&|p| p.x > p.w)
        || all(&|p| p.x < -p.w)
        || all(&|p| p.y > p.w)
        || all(&|p| p.y < -p.w)
        || all(&|p| p.z > p.w)
        || all(&|p| p.z < -p.w)
}

/// Tessellate `triangles` over `vertices` (see the module docs).
///
/// # Errors
/// [`TooManyTriangles`] when the result would pass `t.max_triangles`.
pub fn tessellate(
    vertices: &[Vertex],
    triangles: &[[u32; 3]],
    t: &Tessellation,
) -> Result<Tessellated, TooManyTriangles> {
    let mut verts = vertices.to_vec();
    let mut clip: Vec<Vec4> = verts
        .iter()
        .map(|v| t.clip_from_world * v.position.extend(1.0))
        .collect();
    let mut mids: HashMap<(u32, u32), u32> = HashMap::new();
    let mut out = Vec::with_capacity(triangles.len());
    let mut stack: Vec<[u32; 3]> = triangles.iter().rev().copied().collect();
    let limit = t.edge_px.max(1e-3);
    while let Some(tri) = stack.pop() {
        if out.len() + stack.len() > t.max_triangles {
            return Err(TooManyTriangles {
                max: t.max_triangles,
            });
        }
        if tri.iter().any(|&k| k as usize >= verts.len()) || outside(tri.map(|k| clip[k as usize]))
        {
            out.push(tri);
            continue;
        }
        let long = |a: u32, b: u32| {
            t.visible_length(clip[a as usize], clip[b as usize])
                .is_some_and(|l| l > limit)
        };
        let split = [0, 1, 2].map(|e| long(tri[e], tri[(e + 1) % 3]));
        if !split.contains(&true) {
            out.push(tri);
            continue;
        }
        let mut mid = |e: usize| -> u32 {
            let (a, b) = (tri[e], tri[(e + 1) % 3]);
            let key = (a.min(b), a.max(b));
            *mids.entry(key).or_insert_with(|| {
                let v = midpoint(&verts[key.0 as usize], &verts[key.1 as usize]);
                clip.push(t.clip_from_world * v.position.extend(1.0));
                verts.push(v);
                (verts.len() - 1) as u32
            })
        };
        let [a, b, c] = tri;
        match split {
            [true, true, true] => {
                let (ab, bc, ca) = (mid(0), mid(1), mid(2));
                stack.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
            }
            [true, false, false] => {
                let ab = mid(0);
                stack.extend([[a, ab, c], [ab, b, c]]);
            }
            [false, true, false] => {
                let bc = mid(1);
                stack.extend([[a, b, bc], [a, bc, c]]);
            }
            [false, false, true] => {
                let ca = mid(2);
                stack.extend([[a, b, ca], [ca, b, c]]);
            }
            [true, true, false] => {
                let (ab, bc) = (mid(0), mid(1));
                stack.extend([[ab, b, bc], [a, ab, bc], [a, bc, c]]);
            }
            [false, true, true] => {
                let (bc, ca) = (mid(1), mid(2));
                stack.extend([[bc, c, ca], [a, b, bc], [a, bc, ca]]);
            }
            [true, false, true] => {
                let (ab, ca) = (mid(0), mid(2));
                stack.extend([[a, ab, ca], [ab, b, c], [ab, c, ca]]);
            }
            [false, false, false] => unreachable!("handled above"),
        }
    }
    Ok(Tessellated {
        vertices: verts,
        triangles: out,
    })
}

/// How [`displace`] reads the height map.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeightFilter {
    /// Trilinear over a footprint as wide as the vertex's longest edge in texture space.
    EdgeMatched,
    /// Level 0, bilinearly (the reference's).
    Level0,
}

/// Move every vertex of `mesh` to `p + scale (h - 1) n` with `h` the red channel of `heights`
/// read at the vertex's `uv` with the mesh's address modes through `filter` (module docs).
/// Vertices without a normal stay.
///
/// # Errors
/// A sampler descriptor error (never for the address modes texel accepts).
pub fn displace(
    mesh: &mut Tessellated,
    heights: &Texture,
    address_modes: (AddressMode, AddressMode),
    scale: f32,
    filter: HeightFilter,
) -> Result<(), texel_texture::TextureError> {
    let mut desc = SamplerDescriptor::from(Filter::Trilinear);
    desc.address_mode_u = address_modes.0;
    desc.address_mode_v = address_modes.1;
    let sampler = Sampler::new(desc)?;
    // Each vertex's longest incident edge in texture space.
    let mut reach = vec![0.0f32; mesh.vertices.len()];
    if filter == HeightFilter::EdgeMatched {
        for tri in &mesh.triangles {
            for e in 0..3 {
                let (a, b) = (tri[e] as usize, tri[(e + 1) % 3] as usize);
                if a >= reach.len() || b >= reach.len() {
                    continue;
                }
                let d = mesh.vertices[a].uv - mesh.vertices[b].uv;
                let len = d.abs().max_element();
                reach[a] = reach[a].max(len);
                reach[b] = reach[b].max(len);
            }
        }
    }
    for (v, &r) in mesh.vertices.iter_mut().zip(&reach) {
        let Some(n) = v.normal.try_normalize() else {
            continue;
        };
        let fp = Footprint {
            u: v.uv.x,
            v: v.uv.y,
            dudx: r,
            dudy: 0.0,
            dvdx: 0.0,
            dvdy: r,
        };
        let h = sampler.sample(heights, &fp)[0];
        v.position += n * (scale * (h - 1.0));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use texel_texture::{Format, Limits};

    /// A square in z = -2 seen head-on, 2 triangles.
    fn square() -> (Vec<Vertex>, Vec<[u32; 3]>) {
        let v = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .map(|&(x, y)| {
                let mut v = Vertex::new(
                    Vec3::new(x, y, -2.0),
                    Vec2::new((x + 1.0) / 2.0, (1.0 - y) / 2.0),
                );
                v.normal = Vec3::Z;
                v
            })
            .collect();
        (v, vec![[0, 1, 2], [0, 2, 3]])
    }

    fn setup(edge_px: f32) -> Tessellation {
        let m = Mat4::perspective_rh_gl(60f32.to_radians(), 1.0, 0.1, 10.0);
        Tessellation {
            clip_from_world: m,
            width: 64,
            height: 64,
            edge_px,
            max_triangles: 1 << 20,
        }
    }

    /// Every projected edge ends within the limit, the area is kept, and every edge inside the
    /// square is shared by exactly two triangles (watertight: no T-junctions).
    #[test]
    fn edges_end_short_and_the_mesh_stays_watertight() {
        let (v, t) = square();
        let s = setup(3.0);
        let out = tessellate(&v, &t, &s).unwrap();
        assert!(out.triangles.len() > 100, "{}", out.triangles.len());
        let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
        let mut area = 0.0;
        for tri in &out.triangles {
            let p = tri.map(|k| out.vertices[k as usize].position);
            // Counter-clockwise seen from +z, as the originals.
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            assert!(n.z > 0.0);
            area += n.z / 2.0;
            for e in 0..3 {
                let (a, b) = (tri[e], tri[(e + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += 1;
                let pa = s.pixel(s.clip_from_world * p[e].extend(1.0)).unwrap();
                let pb = s
                    .pixel(s.clip_from_world * p[(e + 1) % 3].extend(1.0))
                    .unwrap();
                assert!(pa.distance(pb) <= 3.0 + 1e-3);
            }
        }
        assert!((area - 4.0).abs() < 1e-3, "{area}");
        for (&(a, b), &count) in &edges {
            let (pa, pb) = (
                out.vertices[a as usize].position,
                out.vertices[b as usize].position,
            );
            let boundary =
                (pa.x.abs() == 1.0 && pb.x == pa.x) || (pa.y.abs() == 1.0 && pb.y == pa.y);
            assert_eq!(count, if boundary { 1 } else { 2 }, "edge {pa} {pb}");
        }
        // Too many triangles is an error, not a hang.
        let tight = Tessellation {
            max_triangles: 50,
            ..s
        };
        assert_eq!(
            tessellate(&v, &t, &tight),
            Err(TooManyTriangles { max: 50 })
        );
    }

    #[test]
    fn triangles_out_of_view_or_short_are_kept() {
        let (v, t) = square();
        assert_eq!(tessellate(&v, &t, &setup(1000.0)).unwrap().triangles, t);
        let behind: Vec<Vertex> = v
            .iter()
            .map(|v| Vertex {
                position: v.position * Vec3::new(1.0, 1.0, -1.0),
                ..*v
            })
            .collect();
        assert_eq!(tessellate(&behind, &t, &setup(1.0)).unwrap().triangles, t);
    }

    /// A floor below the eye that runs from behind it to far in front (as a wall seen along its
    /// length does): every edge of its two triangles has an end behind the eye, yet its visible
    /// part is split until the edges in view are short. (Measuring only edges with both ends in
    /// front left such meshes, and the reference's true relief, untessellated.)
    #[test]
    fn edges_that_cross_the_near_plane_split_by_their_visible_part() {
        let v: Vec<Vertex> = [(-1.0, 1.0), (1.0, 1.0), (1.0, -8.0), (-1.0, -8.0)]
            .iter()
            .map(|&(x, z)| {
                let mut v = Vertex::new(Vec3::new(x, -0.5, z), Vec2::new(x, z));
                v.normal = Vec3::Y;
                v
            })
            .collect();
        let t = vec![[0, 1, 2], [0, 2, 3]];
        let s = setup(4.0);
        let out = tessellate(&v, &t, &s).unwrap();
        assert!(out.triangles.len() > 200, "{}", out.triangles.len());
        for tri in &out.triangles {
            let c = tri.map(|k| s.clip_from_world * out.vertices[k as usize].position.extend(1.0));
            if outside(c) {
                continue;
            }
            for e in 0..3 {
                let l = s.visible_length(c[e], c[(e + 1) % 3]);
                assert!(l.is_none_or(|l| l <= 4.0 + 1e-3), "{l:?}");
            }
        }
    }

    /// Heights 0.25 everywhere move the square `0.75 s` down its normal; a ramp displaces each
    /// vertex by its own height (level 0 reads it exactly at texel centres' interpolation).
    #[test]
    fn displacement_moves_along_the_normal_by_the_height() {
        let (v, t) = square();
        let flat = Texture::from_fn(8, 8, Format::Rgba32Float, &Limits::default(), |_, _| {
            [0.25, 0.0, 0.0, 1.0]
        })
        .unwrap();
        let mut mesh = tessellate(&v, &t, &setup(8.0)).unwrap();
        let modes = (AddressMode::ClampToEdge, AddressMode::ClampToEdge);
        for filter in [HeightFilter::EdgeMatched, HeightFilter::Level0] {
            let mut m = mesh.clone();
            displace(&mut m, &flat, modes, 0.4, filter).unwrap();
            for (a, b) in m.vertices.iter().zip(&mesh.vertices) {
                assert!((a.position - b.position - Vec3::new(0.0, 0.0, -0.3)).length() < 1e-6);
            }
        }
        // A ramp in u over 64 texels: level 0 at a vertex is the ramp's value there.
        let ramp = Texture::from_fn(64, 64, Format::Rgba32Float, &Limits::default(), |i, _| {
            [(i as f32 + 0.5) / 64.0, 0.0, 0.0, 1.0]
        })
        .unwrap();
        let before = mesh.clone();
        displace(&mut mesh, &ramp, modes, 1.0, HeightFilter::Level0).unwrap();
        for (a, b) in mesh.vertices.iter().zip(&before.vertices) {
            let u = b.uv.x.clamp(0.5 / 64.0, 63.5 / 64.0);
            assert!((a.position.z - (b.position.z + u - 1.0)).abs() < 1e-5);
        }
    }
}
