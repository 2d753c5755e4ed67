//! texel's BVH against the `bvh` crate (0.13, the crate the issue names) on the rays of an ambient
//! occlusion bake: the 100 002-triangle knot (`knot_mesh(1000, 50)`), rays from random surface
//! points in cosine-weighted directions, any distance. Both answer "occluded?" for the same rays
//! (checked equal); the `bvh` crate's traversal yields the triangles whose boxes the ray meets and
//! the same Möller-Trumbore test decides, stopping at the first hit. One thread.

use std::time::Instant;

use bvh::aabb::{Aabb, Bounded};
use bvh::bounding_hierarchy::BHShape;
use glam::Vec3;
use nalgebra::{Point3, Vector3};
use texel_prepare::bvh::{hits_triangle, Bvh};
use texel_texture::base::rng::SplitMix64;

struct Shape {
    tri: [u32; 3],
    lo: Vec3,
    hi: Vec3,
    index: usize,
}

impl Bounded<f32, 3> for Shape {
    fn aabb(&self) -> Aabb<f32, 3> {
        Aabb::with_bounds(
            Point3::new(self.lo.x, self.lo.y, self.lo.z),
            Point3::new(self.hi.x, self.hi.y, self.hi.z),
        )
    }
}

impl BHShape<f32, 3> for Shape {
    fn set_bh_node_index(&mut self, index: usize) {
        self.index = index;
    }
    fn bh_node_index(&self) -> usize {
        self.index
    }
}

fn main() {
    let m = texel::scene::knot_mesh(1000, 50);
    let p = &m.positions;
    let n_rays = 2_000_000;
    let mut rng = SplitMix64::new(1);
    let mut rays = Vec::with_capacity(n_rays);
    while rays.len() < n_rays {
        let k = (rng.next_u64() % m.triangles.len() as u64) as usize;
        let [a, b, c] = m.triangles[k].map(|i| p[i as usize]);
        let (mut s, mut t) = (rng.next_f32(), rng.next_f32());
        if s + t > 1.0 {
            (s, t) = (1.0 - s, 1.0 - t);
        }
        let n = (b - a).cross(c - a).normalize();
        let (tx, ty) = n.any_orthonormal_pair();
        let (u1, u2) = (rng.next_f32(), rng.next_f32());
        let r = u1.sqrt();
        let (sn, cs) = (std::f32::consts::TAU * u2).sin_cos();
        let d = tx * (r * cs) + ty * (r * sn) + n * (1.0 - u1).sqrt();
        rays.push((a + (b - a) * s + (c - a) * t + n * 1e-4, d, k as u32));
    }

    let t0 = Instant::now();
    let ours = Bvh::new(p, &m.triangles);
    let build_ours = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let hit_ours: Vec<bool> = rays
        .iter()
        .map(|&(o, d, k)| ours.occluded(o, d, f32::INFINITY, k))
        .collect();
    let trace_ours = t0.elapsed().as_secs_f64();

    let mut shapes: Vec<Shape> = m
        .triangles
        .iter()
        .map(|&tri| {
            let [a, b, c] = tri.map(|i| p[i as usize]);
            Shape {
                tri,
                lo: a.min(b).min(c),
                hi: a.max(b).max(c),
                index: 0,
            }
        })
        .collect();
    let t0 = Instant::now();
    let theirs = bvh::bvh::Bvh::build(&mut shapes);
    let build_theirs = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let hit_theirs: Vec<bool> = rays
        .iter()
        .map(|&(o, d, k)| {
            let ray = bvh::ray::Ray::new(Point3::new(o.x, o.y, o.z), Vector3::new(d.x, d.y, d.z));
            theirs.traverse_iterator(&ray, &shapes).any(|s| {
                s.tri != m.triangles[k as usize] && hits_triangle(p, s.tri, o, d, f32::INFINITY)
            })
        })
        .collect();
    let trace_theirs = t0.elapsed().as_secs_f64();
    let differ = hit_ours
        .iter()
        .zip(&hit_theirs)
        .filter(|(a, b)| a != b)
        .count();
    let occluded = hit_ours.iter().filter(|&&h| h).count();
    println!("{} triangles, {n_rays} rays ({:.1} % occluded), one thread; answers differ on {differ} rays", m.triangles.len(), 100.0 * occluded as f64 / n_rays as f64);
    println!("| BVH | build ms | M rays/s |");
    println!("|---|--:|--:|");
    println!(
        "| texel_prepare::bvh | {:.0} | {:.2} |",
        build_ours * 1e3,
        n_rays as f64 / trace_ours / 1e6
    );
    println!(
        "| bvh 0.13 | {:.0} | {:.2} |",
        build_theirs * 1e3,
        n_rays as f64 / trace_theirs / 1e6
    );
}
