//! Watertightness: meshes with shared edges cover every pixel exactly once.

mod common;

use common::{screen_vertex, white, Rng};
use glam::Mat4;
use texel_raster::setup::setup_draws;
use texel_raster::{render, DrawCall, RenderSettings, Vertex};

/// Count, for every pixel, how many set-up triangles cover its centre.
fn coverage_counts(vertices: &[Vertex], triangles: &[[u32; 3]], w: u32, h: u32) -> Vec<u32> {
    let (tex, sampler) = white();
    let draw = DrawCall {
        vertices,
        triangles,
        texture: &tex,
        sampler: &sampler,
        clip_from_world: Mat4::IDENTITY,
        material: None,
        uv_mapping: None,
    };
    let settings = RenderSettings::new(w, h);
    let setups = setup_draws(&settings, &[draw]).unwrap();
    let mut counts = vec![0u32; (w * h) as usize];
    for t in &setups {
        let Some([i0, j0, i1, j1]) = t.bbox else {
            continue;
        };
        for j in j0..=j1 {
            for i in i0..=i1 {
                counts[(j * w + i) as usize] += u32::from(t.covers(i, j));
            }
        }
    }
    // The renderer agrees: every pixel is covered.
    let frame = render(&settings, &[draw]).unwrap();
    assert_eq!(frame.covered_pixels(), (w * h) as usize);
    counts
}

fn assert_exactly_once(counts: &[u32], w: u32, what: &str) {
    for (k, &c) in counts.iter().enumerate() {
        assert_eq!(
            c,
            1,
            "{what}: pixel ({}, {}) covered {c} times",
            k as u32 % w,
            k as u32 / w
        );
    }
}

/// A grid over (and beyond) the frame; interior vertices jittered by up to `jitter` cells.
fn grid(
    w: u32,
    h: u32,
    nx: u32,
    ny: u32,
    jitter: f64,
    rng: &mut Rng,
) -> (Vec<Vertex>, Vec<[u32; 3]>) {
    let (x0, y0, x1, y1) = (-3.0, -3.0, f64::from(w) + 3.0, f64::from(h) + 3.0);
    let (cw, ch) = ((x1 - x0) / f64::from(nx), (y1 - y0) / f64::from(ny));
    let mut vertices = Vec::new();
    for b in 0..=ny {
        for a in 0..=nx {
            let interior = a > 0 && a < nx && b > 0 && b < ny;
            let (jx, jy) = if interior {
                (
                    (rng.next_f64() - 0.5) * 2.0 * jitter * cw,
                    (rng.next_f64() - 0.5) * 2.0 * jitter * ch,
                )
            } else {
                (0.0, 0.0)
            };
            vertices.push(screen_vertex(
                x0 + f64::from(a) * cw + jx,
                y0 + f64::from(b) * ch + jy,
                w,
                h,
            ));
        }
    }
    let mut triangles = Vec::new();
    for b in 0..ny {
        for a in 0..nx {
            let k = b * (nx + 1) + a;
            let (p00, p10, p01, p11) = (k, k + 1, k + nx + 1, k + nx + 2);
            // Alternate the diagonal and the winding, so both orientations are exercised.
            if (a + b) % 2 == 0 {
                triangles.push([p00, p10, p11]);
                triangles.push([p00, p01, p11]);
            } else {
                triangles.push([p10, p01, p00]);
                triangles.push([p10, p11, p01]);
            }
        }
    }
    (vertices, triangles)
}

#[test]
fn jittered_grids_cover_each_pixel_once() {
    for seed in 0..6 {
        let mut rng = Rng::new(seed);
        let (v, t) = grid(97, 61, 23, 17, 0.3, &mut rng);
        let counts = coverage_counts(&v, &t, 97, 61);
        assert_exactly_once(&counts, 97, &format!("grid seed {seed}"));
    }
}

#[test]
fn grid_through_pixel_centres_covers_each_pixel_once() {
    // Vertices and horizontal/vertical edges exactly on pixel centres: every tie goes through the
    // top-left rule.
    let (w, h) = (64, 48);
    let mut vertices = Vec::new();
    let (nx, ny) = (9u32, 7u32);
    for b in 0..=ny {
        for a in 0..=nx {
            let x = if a == 0 {
                -2.0
            } else if a == nx {
                66.0
            } else {
                f64::from(a * 7) + 0.5
            };
            let y = if b == 0 {
                -2.0
            } else if b == ny {
                50.0
            } else {
                f64::from(b * 7) + 0.5
            };
            vertices.push(screen_vertex(x, y, w, h));
        }
    }
    let mut triangles = Vec::new();
    for b in 0..ny {
        for a in 0..nx {
            let k = b * (nx + 1) + a;
            triangles.push([k, k + 1, k + nx + 2]);
            triangles.push([k, k + nx + 2, k + nx + 1]);
        }
    }
    assert_exactly_once(
        &coverage_counts(&vertices, &triangles, w, h),
        w,
        "centre grid",
    );
}

#[test]
fn random_fans_cover_each_pixel_once() {
    let (w, h) = (83, 59);
    for seed in 0..6 {
        let mut rng = Rng::new(100 + seed);
        let centre = (rng.next_f64() * f64::from(w), rng.next_f64() * f64::from(h));
        let mut vertices = vec![screen_vertex(centre.0, centre.1, w, h)];
        // A closed ring around the frame's border (outside it), at random positions along each side.
        let n = 40;
        let (x0, y0, x1, y1) = (-2.0, -2.0, f64::from(w) + 2.0, f64::from(h) + 2.0);
        let perimeter = 2.0 * ((x1 - x0) + (y1 - y0));
        let mut ts: Vec<f64> = (0..n).map(|_| rng.next_f64() * perimeter).collect();
        ts.extend([
            0.0,
            x1 - x0,
            (x1 - x0) + (y1 - y0),
            2.0 * (x1 - x0) + (y1 - y0),
        ]);
        ts.sort_by(|a, b| a.partial_cmp(b).unwrap());
        for s in ts {
            let (x, y) = if s < x1 - x0 {
                (x0 + s, y0)
            } else if s < (x1 - x0) + (y1 - y0) {
                (x1, y0 + s - (x1 - x0))
            } else if s < 2.0 * (x1 - x0) + (y1 - y0) {
                (x1 - (s - (x1 - x0) - (y1 - y0)), y1)
            } else {
                (x0, y1 - (s - 2.0 * (x1 - x0) - (y1 - y0)))
            };
            vertices.push(screen_vertex(x, y, w, h));
        }
        let m = vertices.len() as u32 - 1;
        let triangles: Vec<[u32; 3]> = (0..m).map(|k| [0, 1 + k, 1 + (k + 1) % m]).collect();
        let counts = coverage_counts(&vertices, &triangles, w, h);
        assert_exactly_once(&counts, w, &format!("fan seed {seed}"));
    }
}
