//! `texel::ao`: the baked ambient occlusion against an independent Monte Carlo estimate, a box on a
//! plane, convex meshes, determinism and bad settings.

use std::sync::atomic::AtomicBool;

use glam::{Vec2, Vec3};
use texel::ao::{bake_ao, AoMap, AoMesh, AoSettings};
use texel::{Error, MemoryBudget, Scene};
use texel_prepare::bvh::hits_triangle;
use texel_texture::base::rng::SplitMix64;

/// A 4 x 4 plane at `y = 0` (uv = `((x + 2) / 4, (z + 2) / 4)`) with a unit box standing on it at
/// the centre. The box's uvs lie outside the map: it occludes but is not baked.
fn box_on_plane() -> AoMesh {
    let mut m = AoMesh::default();
    let mut quad = |corners: [Vec3; 4], uv: bool| {
        let base = m.positions.len() as u32;
        let n = (corners[1] - corners[0])
            .cross(corners[2] - corners[0])
            .normalize();
        for c in corners {
            m.positions.push(c);
            m.normals.push(n);
            m.uvs.push(if uv {
                Vec2::new((c.x + 2.0) / 4.0, (c.z + 2.0) / 4.0)
            } else {
                Vec2::splat(5.0)
            });
        }
        m.triangles
            .extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    };
    let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    quad(
        [
            p(-2., 0., -2.),
            p(-2., 0., 2.),
            p(2., 0., 2.),
            p(2., 0., -2.),
        ],
        true,
    );
    let h = 0.5;
    // The box's faces, counter-clockwise from outside.
    let faces = [
        [p(-h, 1., -h), p(-h, 1., h), p(h, 1., h), p(h, 1., -h)], // top
        [p(-h, 0., h), p(h, 0., h), p(h, 1., h), p(-h, 1., h)],   // +z
        [p(h, 0., -h), p(-h, 0., -h), p(-h, 1., -h), p(h, 1., -h)], // -z
        [p(h, 0., h), p(h, 0., -h), p(h, 1., -h), p(h, 1., h)],   // +x
        [p(-h, 0., -h), p(-h, 0., h), p(-h, 1., h), p(-h, 1., -h)], // -x
        [p(-h, 0., -h), p(h, 0., -h), p(h, 0., h), p(-h, 0., h)], // bottom
    ];
    for f in faces {
        quad(f, false);
    }
    m
}

fn bake(mesh: &AoMesh, settings: &AoSettings) -> Result<AoMap, Error> {
    let mut budget = MemoryBudget::new(1 << 30, "the test's 1 GiB");
    bake_ao(
        mesh,
        settings,
        &mut budget,
        &|_| {},
        &AtomicBool::new(false),
    )
}

fn at(map: &AoMap, x: u32, y: u32) -> f32 {
    map.values[(y * map.size + x) as usize]
}

/// The world point of the plane at texel `(x, y)`'s centre of a `size` map.
fn plane_point(size: u32, x: u32, y: u32) -> Vec3 {
    let u = (x as f32 + 0.5) / size as f32;
    let v = (y as f32 + 0.5) / size as f32;
    Vec3::new(u * 4.0 - 2.0, 0.0, v * 4.0 - 2.0)
}

#[test]
fn texel_matches_an_independent_monte_carlo_estimate() {
    let size = 40;
    let rays = 1024;
    let mesh = box_on_plane();
    let map = bake(
        &mesh,
        &AoSettings {
            size,
            rays,
            ..AoSettings::default()
        },
    )
    .unwrap();
    // Independent estimate: uniform hemisphere directions (not cosine-weighted), weight
    // 2 cos(theta), every triangle tested (no hierarchy), another generator.
    let mut rng = SplitMix64::new(12345);
    for (x, y) in [(26, 20), (27, 23), (22, 27), (30, 30), (12, 5)] {
        let p = plane_point(size, x, y) + Vec3::Y * 1e-4;
        let n = 40_000;
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let z = rng.next_f32();
            let phi = std::f32::consts::TAU * rng.next_f32();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let d = Vec3::new(r * phi.cos(), z, r * phi.sin());
            let blocked = mesh
                .triangles
                .iter()
                .skip(2)
                .any(|&t| hits_triangle(&mesh.positions, t, p, d, f32::INFINITY));
            let w = if blocked { 0.0 } else { 2.0 * f64::from(z) };
            sum += w;
            sum2 += w * w;
        }
        let mean = sum / n as f64;
        let se_independent = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
        let baked = f64::from(at(&map, x, y));
        // The baked texel's error: at most a binomial's (stratification only lowers it).
        let se_baked = (baked * (1.0 - baked) / f64::from(rays)).sqrt();
        let se = (se_independent.powi(2) + se_baked.powi(2)).sqrt().max(1e-3);
        assert!(
            (baked - mean).abs() < 4.0 * se,
            "texel ({x}, {y}): baked {baked}, independent {mean} +- {se}"
        );
    }
}

#[test]
fn a_plane_under_a_box_is_darker_near_the_box() {
    let size = 64;
    let map = bake(
        &box_on_plane(),
        &AoSettings {
            size,
            rays: 256,
            ..AoSettings::default()
        },
    )
    .unwrap();
    // The box spans texels 24..40 of 64; along the row through its centre, going out from its
    // +x side, the plane brightens.
    let row = 32;
    let profile: Vec<f32> = (40..64).map(|x| at(&map, x, row)).collect();
    assert!(profile[0] < 0.7, "{profile:?}");
    assert!(profile[23] > 0.9, "{profile:?}");
    for w in profile.windows(4).step_by(4) {
        assert!(w[0] < w[3] + 0.02, "{profile:?}");
    }
    // Under the box: fully occluded. The far corner sees almost the whole sky.
    assert_eq!(at(&map, 32, 32), 0.0);
    assert!(at(&map, 0, 0) > 0.95);
    // The box's own texels are outside the map: 12 triangles skipped.
    assert_eq!(map.skipped_triangles, 12);
    assert_eq!(map.sampled, 64 * 64);
    assert_eq!(map.rays, 64 * 64 * 256);

    // A maximum distance of 0.25 lets the far plane see everything, and the box's side less.
    let near = bake(
        &box_on_plane(),
        &AoSettings {
            size,
            rays: 256,
            max_distance: Some(0.25),
            ..AoSettings::default()
        },
    )
    .unwrap();
    assert_eq!(at(&near, 60, row), 1.0);
    assert_eq!(at(&near, 4, 4), 1.0);
    assert!(at(&near, 40, row) > at(&map, 40, row));
    assert!(at(&near, 40, row) < 0.9);
}

#[test]
fn unoccluded_convex_meshes_bake_to_one() {
    // The cube (flat faces, uvs overlapping on each face: all bake 1 anyway) and the sphere
    // (smooth normals leaning off its faces: the mirrored directions keep it exact).
    for name in ["builtin:cube", "builtin:sphere"] {
        let scene = Scene::load(name).unwrap();
        let mesh = AoMesh::from_meshes(&scene.meshes);
        let map = bake(
            &mesh,
            &AoSettings {
                size: 32,
                rays: 64,
                ..AoSettings::default()
            },
        )
        .unwrap();
        assert!(map.sampled > 0);
        assert!(map.values.iter().all(|&v| v == 1.0), "{name}");
    }
}

#[test]
fn the_same_seed_gives_the_same_map_on_any_thread_count() {
    let mesh = box_on_plane();
    let s = AoSettings {
        size: 24,
        rays: 37,
        seed: 9,
        ..AoSettings::default()
    };
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| bake(&mesh, &s).unwrap())
    };
    let one = on(1);
    assert!(one == on(3));
    let other = bake(&mesh, &AoSettings { seed: 10, ..s }).unwrap();
    assert!(one.values != other.values);
}

#[test]
fn the_margin_fills_around_islands_and_no_further() {
    // One small triangle island in the middle of a 32 x 32 map.
    let mesh = AoMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Z],
        normals: vec![Vec3::Y; 3],
        uvs: vec![
            Vec2::new(0.45, 0.45),
            Vec2::new(0.55, 0.45),
            Vec2::new(0.45, 0.55),
        ],
        triangles: vec![[0, 2, 1]],
    };
    let s = AoSettings {
        size: 32,
        rays: 16,
        margin: Some(2),
        ..AoSettings::default()
    };
    let map = bake(&mesh, &s).unwrap();
    // A lone triangle sees the whole sky; the corner beyond the margin is the background, 1 too:
    // what the margin changes is which texels were filled.
    assert!(map.values.iter().all(|&v| v == 1.0));
    let all = bake(&mesh, &AoSettings { margin: None, ..s }).unwrap();
    assert_eq!(map.sampled, all.sampled);
    assert_eq!(map.sampled + all.filled, 32 * 32);
    assert!(map.filled < all.filled && map.filled > 0);
}

#[test]
fn bad_settings_and_meshes_are_errors() {
    let mesh = box_on_plane();
    let base = AoSettings {
        size: 8,
        rays: 4,
        ..AoSettings::default()
    };
    let bad = [
        AoSettings { size: 0, ..base },
        AoSettings {
            size: 16385,
            ..base
        },
        AoSettings { rays: 0, ..base },
        AoSettings {
            rays: 70_000,
            ..base
        },
        AoSettings {
            max_distance: Some(f32::NAN),
            ..base
        },
        AoSettings {
            max_distance: Some(-1.0),
            ..base
        },
    ];
    for s in bad {
        let e = bake(&mesh, &s).unwrap_err();
        assert!(matches!(e, Error::Bake(_)), "{s:?}: {e}");
    }
    let mut broken = mesh.clone();
    broken.triangles.push([0, 1, 999]);
    assert!(matches!(bake(&broken, &base), Err(Error::Bake(_))));
    let mut short = mesh.clone();
    short.uvs.pop();
    assert!(matches!(bake(&short, &base), Err(Error::Bake(_))));
    assert!(matches!(
        bake(&AoMesh::default(), &base),
        Err(Error::Bake(_))
    ));
    // A map the budget cannot hold is refused before anything is allocated.
    let mut small = MemoryBudget::new(1 << 20, "1 MiB");
    let e = bake_ao(
        &mesh,
        &AoSettings { size: 4096, ..base },
        &mut small,
        &|_| {},
        &AtomicBool::new(false),
    )
    .unwrap_err();
    assert!(matches!(e, Error::OverBudget { .. }), "{e}");
    // A cancelled bake stops with an error.
    let e = bake_ao(
        &mesh,
        &base,
        &mut MemoryBudget::new(1 << 30, "1 GiB"),
        &|_| {},
        &AtomicBool::new(true),
    )
    .unwrap_err();
    assert!(matches!(e, Error::Cancelled));
    // Non-finite positions: the triangle is skipped, the rest bakes.
    let mut nan = mesh.clone();
    nan.positions[0] = Vec3::NAN;
    let map = bake(&nan, &base).unwrap();
    assert!(map.skipped_triangles >= 13);
    assert!(map.values.iter().all(|v| v.is_finite()));
}
