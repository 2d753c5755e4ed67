//! A bounding volume hierarchy over triangles for occlusion ("any hit") rays: what the ambient
//! occlusion baker ([`crate::ao`]) casts, a few hundred rays per texel.
//!
//! - **Build**: top-down, binned surface area heuristic (Wald 2007, "On fast construction of
//!   SAH-based bounding volume hierarchies"): 12 bins over the centroids' extent on each axis, the
//!   split of least `1 + (A_L N_L + A_R N_R) / A` against a leaf's `N`, leaves of at most
//!   [`MAX_LEAF`] triangles once splitting no longer pays. Below depth [`MEDIAN_DEPTH`] nodes split
//!   at the median instead, so the depth stays under `MEDIAN_DEPTH + log2(n)` whatever the input
//!   (and the traversal stack is a fixed array).
//! - **Nodes**: 32 bytes, children stored next to each other; boxes widened by a relative
//!   `2^-20` so that a ray grazing a face is never culled from a box its triangle lies in (the
//!   traversal then finds exactly the hits a brute-force loop finds; tested).
//! - **Triangles**: stored as `(v0, e1, e2)` in leaf order, intersected with Möller & Trumbore
//!   (1997), two-sided.
//! - **Query**: [`Bvh::occluded`] stops at the first hit in `(0, t_max)`, visiting the nearer child
//!   first.
//!
//! Measured against the `bvh` crate: docs/guide/environment.md and docs/decisions.md
//! ("Decisions (ambient occlusion bake)").

use glam::Vec3;

/// Most triangles in a leaf.
pub const MAX_LEAF: usize = 4;
/// Depth from which nodes split at the median rather than by the SAH.
pub const MEDIAN_DEPTH: usize = 48;
/// Centroid bins per axis.
const BINS: usize = 12;
/// Traversal stack entries: `MEDIAN_DEPTH` plus a median split's `log2(u32::MAX)`.
const STACK: usize = MEDIAN_DEPTH + 34;

#[derive(Clone, Copy, Debug)]
struct Node {
    min: Vec3,
    /// Interior: index of the left child (the right one is `first + 1`). Leaf: first triangle.
    first: u32,
    max: Vec3,
    /// Triangles in the leaf; 0 for an interior node.
    count: u32,
}

#[derive(Clone, Copy, Debug)]
struct Tri {
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
    /// Index in the triangle list the hierarchy was built from.
    id: u32,
}

/// A bounding volume hierarchy over a triangle list, for [`Bvh::occluded`] queries.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    tris: Vec<Tri>,
}

#[derive(Clone, Copy)]
struct Bounds {
    min: Vec3,
    max: Vec3,
}

impl Bounds {
    const EMPTY: Bounds = Bounds {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    fn grow(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    fn join(&mut self, b: &Bounds) {
        self.min = self.min.min(b.min);
        self.max = self.max.max(b.max);
    }

    /// Half the surface area (the SAH only compares ratios); 0 when empty.
    fn half_area(&self) -> f32 {
        let d = (self.max - self.min).max(Vec3::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

impl Bvh {
    /// The hierarchy over `triangles` (indices into `positions`). Triangles with an index out of
    /// range or a non-finite corner are left out (they can occlude nothing); degenerate ones stay
    /// and are never hit.
    pub fn new(positions: &[Vec3], triangles: &[[u32; 3]]) -> Self {
        let mut tris = Vec::with_capacity(triangles.len());
        let mut boxes = Vec::with_capacity(triangles.len());
        for (id, t) in triangles.iter().enumerate() {
            let p = t.map(|k| positions.get(k as usize).copied().unwrap_or(Vec3::NAN));
            if !p.iter().all(|q| q.is_finite()) {
                continue;
            }
            let mut b = Bounds::EMPTY;
            p.iter().for_each(|&q| b.grow(q));
            boxes.push(b);
            tris.push(Tri {
                v0: p[0],
                e1: p[1] - p[0],
                e2: p[2] - p[0],
                id: id as u32,
            });
        }
        let mut order: Vec<u32> = (0..tris.len() as u32).collect();
        let centroids: Vec<Vec3> = boxes.iter().map(|b| (b.min + b.max) * 0.5).collect();
        let mut nodes = vec![Node {
            min: Vec3::ZERO,
            first: 0,
            max: Vec3::ZERO,
            count: 0,
        }];
        // (node, start, end, depth) still to build.
        let mut todo = vec![(0usize, 0usize, order.len(), 0usize)];
        while let Some((at, start, end, depth)) = todo.pop() {
            let refs = &mut order[start..end];
            let mut b = Bounds::EMPTY;
            let mut cb = Bounds::EMPTY;
            for &r in refs.iter() {
                b.join(&boxes[r as usize]);
                cb.grow(centroids[r as usize]);
            }
            let pad = (b.max - b.min).abs().max(b.min.abs().max(b.max.abs())) * (1.0 / 1048576.0);
            nodes[at].min = b.min - pad;
            nodes[at].max = b.max + pad;
            let n = refs.len();
            let split = if n <= MAX_LEAF {
                None
            } else if depth >= MEDIAN_DEPTH {
                Some(median_split(refs, &centroids, &cb))
            } else {
                sah_split(refs, &boxes, &centroids, &b, &cb)
                    .or_else(|| (n > 4 * MAX_LEAF).then(|| median_split(refs, &centroids, &cb)))
            };
            match split {
                None => {
                    nodes[at].first = start as u32;
                    nodes[at].count = n as u32;
                }
                Some(mid) => {
                    let left = nodes.len();
                    nodes[at].first = left as u32;
                    nodes[at].count = 0;
                    nodes.extend([nodes[at]; 2]);
                    todo.push((left, start, start + mid, depth + 1));
                    todo.push((left + 1, start + mid, end, depth + 1));
                }
            }
        }
        if tris.is_empty() {
            // An empty root box that no ray enters.
            nodes[0].min = Vec3::splat(f32::INFINITY);
            nodes[0].max = Vec3::splat(f32::NEG_INFINITY);
        }
        let tris = order.iter().map(|&r| tris[r as usize]).collect();
        Bvh { nodes, tris }
    }

    /// Triangles in the hierarchy.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    /// Whether the hierarchy holds no triangle.
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// Whether the ray `origin + t dir` hits some triangle other than `skip` (an index of the
    /// list the hierarchy was built from; `u32::MAX` skips none) at `0 < t < t_max`. `dir` need
    /// not be normalised (`t` is in its units); `t_max` may be infinite. A ray with a non-finite
    /// origin or direction hits nothing.
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32, skip: u32) -> bool {
        if self.tris.is_empty() || !origin.is_finite() || !dir.is_finite() {
            return false;
        }
        let inv = dir.recip();
        let mut stack = [0u32; STACK];
        let mut sp = 0;
        if slab(&self.nodes[0], origin, inv, t_max).is_none() {
            return false;
        }
        let mut at = 0usize;
        loop {
            let node = &self.nodes[at];
            if node.count > 0 {
                let leaf = &self.tris[node.first as usize..(node.first + node.count) as usize];
                if leaf
                    .iter()
                    .any(|t| t.id != skip && hit(t, origin, dir, t_max))
                {
                    return true;
                }
            } else {
                let l = node.first as usize;
                let tl = slab(&self.nodes[l], origin, inv, t_max);
                let tr = slab(&self.nodes[l + 1], origin, inv, t_max);
                match (tl, tr) {
                    (Some(a), Some(b)) => {
                        let (near, far) = if a <= b { (l, l + 1) } else { (l + 1, l) };
                        stack[sp] = far as u32;
                        sp += 1;
                        at = near;
                        continue;
                    }
                    (Some(_), None) => {
                        at = l;
                        continue;
                    }
                    (None, Some(_)) => {
                        at = l + 1;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            at = stack[sp] as usize;
        }
    }
}

/// The split of `refs` (reordered in place: the first `k` go left) of least SAH cost, or `None`
/// where a leaf costs less (or every centroid is the same point).
fn sah_split(
    refs: &mut [u32],
    boxes: &[Bounds],
    centroids: &[Vec3],
    b: &Bounds,
    cb: &Bounds,
) -> Option<usize> {
    let extent = cb.max - cb.min;
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, bins on the left)
    for axis in 0..3 {
        if extent[axis].is_nan() || extent[axis] <= 0.0 {
            continue;
        }
        let bin_of = |r: u32| bin(centroids[r as usize][axis], cb.min[axis], extent[axis]);
        let mut count = [0usize; BINS];
        let mut bounds = [Bounds::EMPTY; BINS];
        for &r in refs.iter() {
            let k = bin_of(r);
            count[k] += 1;
            bounds[k].join(&boxes[r as usize]);
        }
        // Areas and counts of the bins right of each plane, swept from the right.
        let mut right_area = [0.0f32; BINS];
        let mut right_count = [0usize; BINS];
        let mut acc = Bounds::EMPTY;
        let mut n = 0;
        for k in (1..BINS).rev() {
            acc.join(&bounds[k]);
            n += count[k];
            right_area[k] = acc.half_area();
            right_count[k] = n;
        }
        let mut acc = Bounds::EMPTY;
        let mut n = 0;
        for k in 1..BINS {
            acc.join(&bounds[k - 1]);
            n += count[k - 1];
            if n == 0 || right_count[k] == 0 {
                continue;
            }
            let cost = acc.half_area() * n as f32 + right_area[k] * right_count[k] as f32;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, k));
            }
        }
    }
    let (cost, axis, k) = best?;
    let area = b.half_area();
    let split_cost = 1.0 + if area > 0.0 { cost / area } else { 0.0 };
    if split_cost >= refs.len() as f32 && refs.len() <= 4 * MAX_LEAF {
        return None;
    }
    let mid = partition(refs, |r| {
        bin(centroids[r as usize][axis], cb.min[axis], extent[axis]) < k
    });
    Some(mid)
}

/// The bin of centroid coordinate `c` over `[lo, lo + extent]` (`extent > 0`).
fn bin(c: f32, lo: f32, extent: f32) -> usize {
    (((c - lo) * (BINS as f32 / extent)) as usize).min(BINS - 1)
}

/// Split `refs` at its median along the centroids' longest axis (by count: equal centroids too).
fn median_split(refs: &mut [u32], centroids: &[Vec3], cb: &Bounds) -> usize {
    let e = cb.max - cb.min;
    let axis = if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    };
    let mid = refs.len() / 2;
    refs.select_nth_unstable_by(mid, |&a, &b| {
        centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
    });
    mid
}

/// Move the elements satisfying `left` to the front; their count.
fn partition(refs: &mut [u32], left: impl Fn(u32) -> bool) -> usize {
    let mut i = 0;
    for j in 0..refs.len() {
        if left(refs[j]) {
            refs.swap(i, j);
            i += 1;
        }
    }
    i
}

/// The ray's entry distance into `node`'s box if it meets it within `[0, t_max)`. `inv` is
/// `1 / dir` per axis (infinite for a zero component; `f32::min`/`max` drop the NaN of `0 * inf`).
#[inline(always)]
fn slab(node: &Node, o: Vec3, inv: Vec3, t_max: f32) -> Option<f32> {
    let t0 = (node.min - o) * inv;
    let t1 = (node.max - o) * inv;
    let near = t0.min(t1);
    let far = t0.max(t1);
    let enter = near.x.max(near.y).max(near.z).max(0.0);
    let exit = far.x.min(far.y).min(far.z).min(t_max);
    (enter <= exit).then_some(enter)
}

/// Möller & Trumbore (1997), two-sided: a hit at `0 < t < t_max` inside the closed triangle.
#[inline(always)]
fn hit(t: &Tri, o: Vec3, d: Vec3, t_max: f32) -> bool {
    let p = d.cross(t.e2);
    let det = t.e1.dot(p);
    if det == 0.0 {
        return false;
    }
    let inv = 1.0 / det;
    let s = o - t.v0;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let q = s.cross(t.e1);
    let v = d.dot(q) * inv;
    if !(v >= 0.0 && u + v <= 1.0) {
        return false;
    }
    let dist = t.e2.dot(q) * inv;
    dist > 0.0 && dist < t_max
}

/// Whether `origin + t dir` hits triangle `k` of the list at `0 < t < t_max`: the same test as
/// [`Bvh::occluded`] without the hierarchy (for brute-force checks).
pub fn hits_triangle(
    positions: &[Vec3],
    tri: [u32; 3],
    origin: Vec3,
    dir: Vec3,
    t_max: f32,
) -> bool {
    let p = tri.map(|k| positions[k as usize]);
    let t = Tri {
        v0: p[0],
        e1: p[1] - p[0],
        e2: p[2] - p[0],
        id: 0,
    };
    hit(&t, origin, dir, t_max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use texel_texture::base::rng::SplitMix64;

    fn random_soup(n: usize, seed: u64) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut r = SplitMix64::new(seed);
        let mut p = Vec::new();
        let mut t = Vec::new();
        for k in 0..n {
            let c = Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) * 10.0;
            for _ in 0..3 {
                p.push(c + Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) - 0.5);
            }
            let b = 3 * k as u32;
            t.push([b, b + 1, b + 2]);
        }
        (p, t)
    }

    #[test]
    fn agrees_with_brute_force() {
        let (p, t) = random_soup(3000, 7);
        let bvh = Bvh::new(&p, &t);
        assert_eq!(bvh.len(), 3000);
        let mut r = SplitMix64::new(99);
        let mut hits = 0;
        for k in 0..4000 {
            let o = Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) * 12.0 - 1.0;
            let d = Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) * 2.0 - 1.0;
            // Axis-aligned directions too: zero components make infinite reciprocals.
            let d = if k % 5 == 0 {
                d * Vec3::new(1.0, 0.0, 0.0)
            } else {
                d
            };
            let t_max = if k % 3 == 0 {
                f32::INFINITY
            } else {
                r.next_f32() * 4.0
            };
            let skip = if k % 7 == 0 {
                (k % 3000) as u32
            } else {
                u32::MAX
            };
            let brute = t
                .iter()
                .enumerate()
                .any(|(i, &tri)| i as u32 != skip && hits_triangle(&p, tri, o, d, t_max));
            assert_eq!(bvh.occluded(o, d, t_max, skip), brute, "ray {k}");
            hits += usize::from(brute);
        }
        // Both outcomes are exercised.
        assert!(hits > 400 && hits < 3600, "{hits}");
    }

    #[test]
    fn depth_is_bounded_on_degenerate_input() {
        // Every triangle at one point: no SAH split exists; the median split keeps going.
        let p = vec![Vec3::ONE; 3];
        let t = vec![[0, 1, 2]; 5000];
        let bvh = Bvh::new(&p, &t);
        assert_eq!(bvh.len(), 5000);
        assert!(!bvh.occluded(Vec3::ZERO, Vec3::ONE, f32::INFINITY, u32::MAX));
        // A thin sliver of triangles along a line, then one ray along it.
        let mut p = Vec::new();
        let mut t = Vec::new();
        for k in 0..5000u32 {
            let x = 1.5f32.powi((k % 60) as i32);
            p.extend([
                Vec3::new(x, 0.0, 0.0),
                Vec3::new(x, 1.0, 0.0),
                Vec3::new(x, 0.0, 1.0),
            ]);
            t.push([3 * k, 3 * k + 1, 3 * k + 2]);
        }
        let bvh = Bvh::new(&p, &t);
        assert!(bvh.occluded(Vec3::new(-1.0, 0.2, 0.2), Vec3::X, f32::INFINITY, u32::MAX));
    }

    #[test]
    fn bad_triangles_and_rays() {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::NAN];
        let bvh = Bvh::new(&p, &[[0, 1, 2], [0, 1, 3], [0, 1, 9]]);
        assert_eq!(bvh.len(), 1);
        let o = Vec3::new(0.2, 0.2, 1.0);
        assert!(bvh.occluded(o, Vec3::NEG_Z, f32::INFINITY, u32::MAX));
        assert!(!bvh.occluded(o, Vec3::NEG_Z, 0.5, u32::MAX));
        assert!(!bvh.occluded(o, Vec3::NEG_Z, f32::INFINITY, 0));
        assert!(!bvh.occluded(o, Vec3::Z, f32::INFINITY, u32::MAX));
        assert!(!bvh.occluded(Vec3::NAN, Vec3::NEG_Z, f32::INFINITY, u32::MAX));
        assert!(!bvh.occluded(o, Vec3::ZERO, f32::INFINITY, u32::MAX));
        let empty = Bvh::new(&[], &[]);
        assert!(empty.is_empty());
        assert!(!empty.occluded(o, Vec3::NEG_Z, f32::INFINITY, u32::MAX));
    }
}
