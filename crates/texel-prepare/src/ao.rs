//! Baked ambient occlusion: the fraction of a cosine-weighted hemisphere of rays that leave the
//! surface unoccluded, stored per texel of the mesh's uv layout (`texel bake-ao`).
//!
//! For a surface point `p` with normal `n`, ambient occlusion is
//! `A(p) = (1 / pi) Int_H V(p, w) (n . w) dw`, where `V` is 1 when the ray from `p` along `w`
//! meets no surface within the maximum distance (Zhukov, Iones & Kronin 1998; Landis 2002).
//! Drawing `w` with density `(n . w) / pi` (Malley's method: uniform points on the unit disc
//! lifted to the hemisphere) makes the estimator the plain mean of `V` over the rays.
//!
//! The steps of [`bake_ao`]:
//! 1. **Texels to surface points.** Every triangle is rasterised in uv space *conservatively*:
//!    every texel whose square the triangle touches gets a sample, at the point of the triangle
//!    nearest the texel's centre (the centre itself where it lies inside). A texel touched by
//!    several triangles takes the nearest point (the first triangle on a tie), so the assignment
//!    does not depend on the order of work. uv `(0, 0)` is the top-left corner of the map, `v`
//!    down (as texel's meshes and glTF); texels outside `[0, 1]^2` are not baked.
//! 2. **Rays.** Per sampled texel, [`AoSettings::rays`] cosine-weighted directions about the
//!    interpolated vertex normal (the face normal where the mesh has none), stratified on an
//!    `s x s` grid (`s = floor(sqrt(rays))`, the rest uniform), from a generator seeded by
//!    `(seed, x, y)` ([`SplitMix64::for_pixel`]): the map is the same for every thread count.
//!    A direction below the triangle's own plane (possible where the smooth normal leans away
//!    from the face) is mirrored above it, so a convex mesh bakes to exactly 1. Rays start
//!    `diagonal * 2^-17` off the surface along the face normal and skip their own triangle; they
//!    are tested against every triangle through a [`Bvh`].
//! 3. **Margin.** Texels no triangle touches are filled outward from the islands, ring by ring
//!    (each takes the mean of its already filled 8-neighbours), up to [`AoSettings::margin`]
//!    rings; beyond that they are 1 (unoccluded). A margin of `M` texels keeps the islands'
//!    values alone in mip levels `0 ..= log2(M) - 1` ([`protected_levels`]): a level-`k` texel
//!    spans `2^k` level-0 texels and bilinear filtering reads one more, so a read just inside an
//!    island reaches up to `2^(k+1)` texels out. 16 texels protect 4 levels; the default fills the
//!    whole map, which protects every level.

use std::sync::atomic::{AtomicBool, Ordering};

use glam::{DVec2, Vec2, Vec3};
use rayon::prelude::*;
use texel_scene::Mesh;
use texel_texture::base::rng::SplitMix64;

use crate::bvh::Bvh;
use crate::{Error, MemoryBudget};

/// Largest map side [`bake_ao`] accepts.
pub const MAX_AO_SIZE: u32 = 16384;
/// Most rays per texel [`bake_ao`] accepts.
pub const MAX_AO_RAYS: u32 = 1 << 16;

/// How [`bake_ao`] bakes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AoSettings {
    /// Side of the square map, texels (1 to [`MAX_AO_SIZE`]).
    pub size: u32,
    /// Rays per texel (1 to [`MAX_AO_RAYS`]).
    pub rays: u32,
    /// Occluders farther than this (world units) do not count; `None`: any distance.
    pub max_distance: Option<f32>,
    /// Rings of texels filled around the uv islands; `None`: the whole map.
    pub margin: Option<u32>,
    /// Seed of the ray directions.
    pub seed: u64,
}

impl Default for AoSettings {
    /// 1024 x 1024, 256 rays, any distance, the whole map filled, seed 0.
    fn default() -> Self {
        AoSettings {
            size: 1024,
            rays: 256,
            max_distance: None,
            margin: None,
            seed: 0,
        }
    }
}

/// The mip levels that a margin of `margin` texels keeps free of the background: levels
/// `0 .. protected_levels(margin)`, that is `floor(log2(margin))` of them (module docs; 0 for a
/// margin under 2).
pub fn protected_levels(margin: u32) -> u32 {
    margin.checked_ilog2().unwrap_or(0)
}

/// The triangles [`bake_ao`] bakes: one list from any number of meshes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AoMesh {
    /// Vertex positions, world units.
    pub positions: Vec<Vec3>,
    /// Vertex normals (zero where a mesh has none: the face normal is used).
    pub normals: Vec<Vec3>,
    /// Texture coordinates, `v` down.
    pub uvs: Vec<Vec2>,
    /// Vertex indices, three per triangle.
    pub triangles: Vec<[u32; 3]>,
}

impl AoMesh {
    /// The meshes' triangles in one list (every mesh bakes into the same map; their uv layouts
    /// should not overlap).
    pub fn from_meshes(meshes: &[Mesh]) -> Self {
        let mut out = AoMesh::default();
        for m in meshes {
            let base = out.positions.len() as u32;
            out.positions.extend(&m.positions);
            out.uvs.extend(&m.uvs);
            match &m.normals {
                Some(n) => out.normals.extend(n),
                None => out
                    .normals
                    .extend(std::iter::repeat_n(Vec3::ZERO, m.positions.len())),
            }
            out.triangles
                .extend(m.triangles.iter().map(|t| t.map(|k| k + base)));
        }
        out
    }

    /// Check that every list agrees in length and every index is in range.
    fn validate(&self) -> Result<(), Error> {
        let n = self.positions.len();
        if self.uvs.len() != n || self.normals.len() != n {
            return Err(Error::Bake(format!(
                "{n} positions but {} uvs and {} normals",
                self.uvs.len(),
                self.normals.len()
            )));
        }
        if let Some(t) = self
            .triangles
            .iter()
            .find(|t| t.iter().any(|&k| k as usize >= n))
        {
            return Err(Error::Bake(format!(
                "triangle {t:?} indexes past the {n} vertices"
            )));
        }
        if self.triangles.is_empty() {
            return Err(Error::Bake("the mesh has no triangles".into()));
        }
        Ok(())
    }

    /// The diagonal of the bounding box of the finite positions (0 when there are none).
    fn diagonal(&self) -> f32 {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for p in self.positions.iter().filter(|p| p.is_finite()) {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        if lo.x <= hi.x {
            (hi - lo).length()
        } else {
            0.0
        }
    }
}

/// A baked map.
#[derive(Clone, Debug, PartialEq)]
pub struct AoMap {
    /// Side of the square map, texels.
    pub size: u32,
    /// Occlusion in `[0, 1]` (1: unoccluded), row-major, row 0 at `v = 0`.
    pub values: Vec<f32>,
    /// Texels with their own sample (touched by a triangle).
    pub sampled: usize,
    /// Texels filled by the margin.
    pub filled: usize,
    /// Rays cast.
    pub rays: u64,
    /// Triangles not baked: zero area in uv or in space, a non-finite corner, or outside the map.
    pub skipped_triangles: usize,
}

impl AoMap {
    /// The map as the 8-bit linear grey image `texel bake-ao` writes (alpha opaque).
    ///
    /// # Errors
    /// [`Error::Quality`] for a map whose side the image type refuses.
    pub fn image(&self) -> Result<texel_quality::Image8, Error> {
        let pixels: Vec<[f32; 4]> = self.values.iter().map(|&v| [v, v, v, 1.0]).collect();
        Ok(texel_quality::Image8::from_linear(
            self.size,
            self.size,
            &pixels,
            texel_quality::Encoding::Linear,
        )?)
    }
}

/// A texel's surface point: triangle `tri` at barycentrics `(1 - b1 - b2, b1, b2)`, `d2` the
/// squared distance (texels) from the texel's centre.
#[derive(Clone, Copy, Debug)]
struct Sample {
    tri: u32,
    b1: f32,
    b2: f32,
    d2: f32,
}

const NONE: Sample = Sample {
    tri: u32::MAX,
    b1: 0.0,
    b2: 0.0,
    d2: f32::INFINITY,
};

/// Bake the ambient occlusion of `mesh` into a `settings.size` square map (module docs).
/// `progress` is called with the number of rows finished since its last call (`size` in all);
/// setting `cancel` stops the bake at the next row with [`Error::Cancelled`]. The map, the
/// texel samples and the hierarchy are charged to `budget` first.
///
/// # Errors
/// [`Error::Bake`] for settings out of range or an inconsistent mesh, [`Error::OverBudget`],
/// [`Error::Cancelled`].
pub fn bake_ao(
    mesh: &AoMesh,
    settings: &AoSettings,
    budget: &mut MemoryBudget,
    progress: &(dyn Fn(u64) + Sync),
    cancel: &AtomicBool,
) -> Result<AoMap, Error> {
    let AoSettings {
        size,
        rays,
        max_distance,
        margin,
        seed,
    } = *settings;
    if !(1..=MAX_AO_SIZE).contains(&size) {
        return Err(Error::Bake(format!(
            "the map size {size} is outside 1 to {MAX_AO_SIZE}"
        )));
    }
    if !(1..=MAX_AO_RAYS).contains(&rays) {
        return Err(Error::Bake(format!(
            "{rays} rays per texel is outside 1 to {MAX_AO_RAYS}"
        )));
    }
    if let Some(d) = max_distance.filter(|d| d.is_nan() || *d <= 0.0) {
        return Err(Error::Bake(format!(
            "the maximum distance {d} is not a positive number"
        )));
    }
    mesh.validate()?;
    let texels = u64::from(size) * u64::from(size);
    budget.take(
        "the occlusion map and its texel samples",
        texels * (std::mem::size_of::<Sample>() + 2 * std::mem::size_of::<f32>()) as u64,
    )?;
    // Nodes (32 bytes, at most 2n) and triangles (40 bytes) of the hierarchy, and its build lists.
    budget.take(
        "the ray-tracing hierarchy",
        mesh.triangles.len() as u64 * (2 * 32 + 40 + 4 + 12 + 24),
    )?;
    let (samples, skipped_triangles) = assign_texels(mesh, size);
    let bvh = Bvh::new(&mesh.positions, &mesh.triangles);
    let t_max = max_distance.unwrap_or(f32::INFINITY);
    let eps = mesh.diagonal() * (1.0 / 131072.0);
    let side = size as usize;
    let mut values = vec![f32::NAN; side * side];
    values
        .par_chunks_mut(side)
        .zip(samples.par_chunks(side))
        .enumerate()
        .try_for_each(|(y, (row, srow))| {
            if cancel.load(Ordering::Relaxed) {
                return Err(Error::Cancelled);
            }
            for (x, (v, s)) in row.iter_mut().zip(srow).enumerate() {
                if s.tri != u32::MAX {
                    let mut rng = SplitMix64::for_pixel(seed, x as u32, y as u32);
                    *v = occlusion(mesh, &bvh, s, rays, t_max, eps, &mut rng);
                }
            }
            progress(1);
            Ok(())
        })?;
    let sampled = samples.iter().filter(|s| s.tri != u32::MAX).count();
    drop(samples);
    let filled = dilate(&mut values, side, margin);
    for v in &mut values {
        if v.is_nan() {
            *v = 1.0;
        }
    }
    Ok(AoMap {
        size,
        values,
        sampled,
        filled,
        rays: sampled as u64 * u64::from(rays),
        skipped_triangles,
    })
}

/// Step 1 (module docs): each texel's nearest surface point over the triangles touching its
/// square; also the count of triangles not baked.
fn assign_texels(mesh: &AoMesh, size: u32) -> (Vec<Sample>, usize) {
    let side = size as usize;
    let mut samples = vec![NONE; side * side];
    let mut skipped = 0;
    let s = f64::from(size);
    for (k, t) in mesh.triangles.iter().enumerate() {
        let p = t.map(|i| mesh.positions[i as usize]);
        let q = t.map(|i| mesh.uvs[i as usize].as_dvec2() * s);
        let area = cross(q[1] - q[0], q[2] - q[0]);
        let spatial = (p[1] - p[0]).cross(p[2] - p[0]).length();
        let flat = area.is_nan() || area.abs() <= 1e-12;
        let collapsed = spatial.is_nan() || spatial <= 0.0 || spatial.is_infinite();
        if flat || collapsed || q.iter().any(|q| !q.is_finite()) {
            skipped += 1;
            continue;
        }
        let sign = area.signum();
        let lo = q[0].min(q[1]).min(q[2]);
        let hi = q[0].max(q[1]).max(q[2]);
        let x0 = lo.x.floor().max(0.0) as usize;
        let y0 = lo.y.floor().max(0.0) as usize;
        let x1 = (hi.x.ceil().min(s) as usize).min(side);
        let y1 = (hi.y.ceil().min(s) as usize).min(side);
        if x0 >= x1 || y0 >= y1 {
            skipped += 1;
            continue;
        }
        // Edge i runs from q[i + 1] to q[i + 2], opposite vertex i; sign * e_i(c) >= 0 inside.
        let edges: [(DVec2, DVec2); 3] = std::array::from_fn(|i| {
            let a = q[(i + 1) % 3];
            (a, q[(i + 2) % 3] - a)
        });
        for y in y0..y1 {
            for x in x0..x1 {
                let corner = DVec2::new(x as f64, y as f64);
                // Separating axes: the box's are the bounding box above; the triangle's edges
                // here, each at the square's corner that is farthest inside.
                let separated = edges.iter().any(|&(a, e)| {
                    let g = DVec2::new(-e.y, e.x) * sign;
                    let far = corner
                        + DVec2::new(
                            f64::from(u8::from(g.x > 0.0)),
                            f64::from(u8::from(g.y > 0.0)),
                        );
                    sign * cross(e, far - a) < 0.0
                });
                if separated {
                    continue;
                }
                let c = corner + 0.5;
                let (b1, b2, d2) = nearest_point(&edges, area, c);
                let slot = &mut samples[y * side + x];
                if (d2 as f32) < slot.d2 {
                    *slot = Sample {
                        tri: k as u32,
                        b1: b1 as f32,
                        b2: b2 as f32,
                        d2: d2 as f32,
                    };
                }
            }
        }
    }
    (samples, skipped)
}

fn cross(a: DVec2, b: DVec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// The point of the triangle of `edges` nearest `c`: its barycentrics `(b1, b2)` (of vertices 1 and 2) and
/// squared distance.
fn nearest_point(edges: &[(DVec2, DVec2); 3], area: f64, c: DVec2) -> (f64, f64, f64) {
    let l: [f64; 3] = std::array::from_fn(|i| cross(edges[i].1, c - edges[i].0) / area);
    if l.iter().all(|&x| x >= 0.0) {
        return (l[1], l[2], 0.0);
    }
    let mut best = (0.0, 0.0, f64::INFINITY);
    for i in 0..3 {
        // Edge from vertex a = i + 1 to vertex b = i + 2.
        let (a, e) = edges[i];
        let t = ((c - a).dot(e) / e.length_squared()).clamp(0.0, 1.0);
        let d2 = (a + e * t - c).length_squared();
        if d2 < best.2 {
            let mut b = [0.0; 3];
            b[(i + 1) % 3] = 1.0 - t;
            b[(i + 2) % 3] = t;
            best = (b[1], b[2], d2);
        }
    }
    best
}

/// Step 2 (module docs): the unoccluded fraction of `rays` cosine-weighted rays from sample `s`.
fn occlusion(
    mesh: &AoMesh,
    bvh: &Bvh,
    s: &Sample,
    rays: u32,
    t_max: f32,
    eps: f32,
    rng: &mut SplitMix64,
) -> f32 {
    let t = mesh.triangles[s.tri as usize];
    let l = Vec3::new(1.0 - s.b1 - s.b2, s.b1, s.b2);
    let [p0, p1, p2] = t.map(|k| mesh.positions[k as usize]);
    let point = p0 * l.x + p1 * l.y + p2 * l.z;
    let mut ng = (p1 - p0).cross(p2 - p0).normalize_or_zero();
    let [n0, n1, n2] = t.map(|k| mesh.normals[k as usize]);
    let ns = (n0 * l.x + n1 * l.y + n2 * l.z).normalize_or_zero();
    let ns = if ns.is_finite() && ns != Vec3::ZERO {
        ns
    } else {
        ng
    };
    if ns.dot(ng) < 0.0 {
        ng = -ng;
    }
    let origin = point + ng * eps;
    let (tx, ty) = ns.any_orthonormal_pair();
    let strata = (rays as f64).sqrt() as u32;
    let inv = 1.0 / strata as f32;
    let mut open = 0u32;
    for k in 0..rays {
        let (r1, r2) = (rng.next_f32(), rng.next_f32());
        let (u1, u2) = if k < strata * strata {
            (
                ((k % strata) as f32 + r1) * inv,
                ((k / strata) as f32 + r2) * inv,
            )
        } else {
            (r1, r2)
        };
        // Malley: a uniform point on the unit disc, lifted to the hemisphere.
        let r = u1.sqrt();
        let (sin, cos) = (std::f32::consts::TAU * u2).sin_cos();
        let mut dir = tx * (r * cos) + ty * (r * sin) + ns * (1.0 - u1).max(0.0).sqrt();
        let below = dir.dot(ng);
        if below < 0.0 {
            dir -= ng * (2.0 * below);
        }
        if !bvh.occluded(origin, dir, t_max, s.tri) {
            open += 1;
        }
    }
    open as f32 / rays as f32
}

/// Step 3 (module docs): fill the NaN texels of `values` ring by ring around the others, at most
/// `margin` rings; the count filled.
fn dilate(values: &mut [f32], side: usize, margin: Option<u32>) -> usize {
    let n = side;
    let neighbours = |i: usize| {
        let (x, y) = ((i % n) as isize, (i / n) as isize);
        (-1isize..=1)
            .flat_map(move |dy| (-1isize..=1).map(move |dx| (x + dx, y + dy)))
            .filter(move |&(a, b)| {
                (a, b) != (x, y) && a >= 0 && b >= 0 && a < n as isize && b < n as isize
            })
            .map(move |(a, b)| b as usize * n + a as usize)
    };
    let mut queued = vec![false; values.len()];
    let mut ring: Vec<usize> = Vec::new();
    for i in 0..values.len() {
        if values[i].is_nan() && neighbours(i).any(|j| !values[j].is_nan()) {
            queued[i] = true;
            ring.push(i);
        }
    }
    let mut filled = 0;
    let mut rings = 0u32;
    while !ring.is_empty() && margin.is_none_or(|m| rings < m) {
        let means: Vec<f32> = ring
            .iter()
            .map(|&i| {
                let (sum, count) = neighbours(i)
                    .filter(|&j| !values[j].is_nan())
                    .fold((0.0f32, 0u32), |(s, c), j| (s + values[j], c + 1));
                sum / count as f32
            })
            .collect();
        for (&i, m) in ring.iter().zip(means) {
            values[i] = m;
        }
        filled += ring.len();
        rings += 1;
        let mut next = Vec::new();
        for &i in &ring {
            for j in neighbours(i) {
                if values[j].is_nan() && !queued[j] {
                    queued[j] = true;
                    next.push(j);
                }
            }
        }
        ring = next;
    }
    filled
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn margin_rule() {
        assert_eq!(protected_levels(16), 4);
        assert_eq!(protected_levels(17), 4);
        assert_eq!(protected_levels(1), 0);
        assert_eq!(protected_levels(0), 0);
        assert_eq!(protected_levels(1024), 10);
    }

    #[test]
    fn dilation_grows_one_ring_at_a_time() {
        // One texel of value 0.5 in a 9 x 9 map: ring r is the square of Chebyshev radius r.
        let n = 9;
        let mut v = vec![f32::NAN; n * n];
        v[4 * n + 4] = 0.5;
        assert_eq!(dilate(&mut v.clone(), n, Some(0)), 0);
        let mut two = v.clone();
        assert_eq!(dilate(&mut two, n, Some(2)), 24);
        assert!(two[2 * n + 2] == 0.5 && two[n + 1].is_nan());
        assert_eq!(dilate(&mut v, n, None), 80);
        assert!(v.iter().all(|&x| x == 0.5));
    }

    #[test]
    fn conservative_assignment_touches_every_texel_a_triangle_overlaps() {
        // A thin sliver across a 16 x 16 map: centre sampling would miss most of its texels.
        let mesh = AoMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: vec![Vec3::ZERO; 3],
            uvs: vec![
                Vec2::new(0.01, 0.02),
                Vec2::new(0.99, 0.97),
                Vec2::new(0.99, 0.99),
            ],
            triangles: vec![[0, 1, 2]],
        };
        let (s, skipped) = assign_texels(&mesh, 16);
        assert_eq!(skipped, 0);
        // Brute force: a texel is touched when a dense grid of points of the sliver falls in it.
        let mut touched = [false; 256];
        for a in 0..=400 {
            for b in 0..=(400 - a) {
                let (l1, l2) = (a as f64 / 400.0, b as f64 / 400.0);
                let uv = mesh.uvs[0].as_dvec2() * (1.0 - l1 - l2)
                    + mesh.uvs[1].as_dvec2() * l1
                    + mesh.uvs[2].as_dvec2() * l2;
                let (x, y) = ((uv.x * 16.0) as usize, (uv.y * 16.0) as usize);
                touched[y.min(15) * 16 + x.min(15)] = true;
            }
        }
        for i in 0..256 {
            if touched[i] {
                assert!(s[i].tri == 0, "texel {i} missed");
            }
            if s[i].tri == 0 {
                // The sample lies on the triangle, at most half a texel diagonal from the centre.
                assert!(s[i].d2 <= 0.5 + 1e-6 && s[i].b1 >= 0.0 && s[i].b2 >= 0.0);
                assert!(s[i].b1 + s[i].b2 <= 1.0 + 1e-6);
            }
        }
        assert!(s.iter().filter(|x| x.tri == 0).count() < 60);
    }
}
