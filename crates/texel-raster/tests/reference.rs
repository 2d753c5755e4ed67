//! The reference renderer: convergence, exactness on flat textures, agreement with the rasterizer.

mod common;

use std::sync::atomic::{AtomicU64, Ordering};

use common::{lab_sampler, screen_vertex, white, Ground};
use texel_raster::{render, render_reference, render_reference_strata, Frame, RenderSettings};
use texel_texture::{Format, Limits, Texture};

/// Mean absolute difference over all channels.
fn mad(a: &Frame, b: &Frame) -> f64 {
    let s: f64 = a
        .color
        .iter()
        .zip(&b.color)
        .map(|(x, y)| (0..4).map(|k| f64::from((x[k] - y[k]).abs())).sum::<f64>())
        .sum();
    s / (4 * a.color.len()) as f64
}

#[test]
fn reference_converges_on_the_ground() {
    let (w, h) = (128, 72);
    let scene = Ground::new(w, h);
    let sampler = lab_sampler(4);
    let s = RenderSettings::new(w, h);
    let r = |n| render_reference(&s, &[scene.draw(&sampler)], n, 3, None).unwrap();
    let (r8, r16, r32) = (r(8), r(16), r(32));
    let (d1, d2) = (mad(&r8, &r16), mad(&r16, &r32));
    // Differences shrink as the sample count grows (stratified sampling: by 2 to 3 per doubling
    // here), and the coarse pair differs by less than 4 times the fine pair.
    assert!(d2 < 0.75 * d1, "d(8,16) = {d1}, d(16,32) = {d2}");
    assert!(d1 < 4.0 * d2, "d(8,16) = {d1}, d(16,32) = {d2}");
    assert!(d1 > 0.0);
    eprintln!("d(8,16) = {d1}, d(16,32) = {d2}");
}

/// Square strata through `render_reference_strata` are `render_reference` bit for bit; a 16 x 32
/// (512-sample) reference lies closer to a 32 x 32 one than an 8 x 8 reference does.
#[test]
fn rectangular_strata() {
    let (w, h) = (96, 54);
    let scene = Ground::new(w, h);
    let sampler = lab_sampler(4);
    let s = RenderSettings::new(w, h);
    let d = [scene.draw(&sampler)];
    let square = render_reference(&s, &d, 6, 9, None).unwrap();
    assert_eq!(
        render_reference_strata(&s, &d, [6, 6], 9, None).unwrap(),
        square
    );
    let r512 = render_reference_strata(&s, &d, [16, 32], 9, None).unwrap();
    let r1024 = render_reference(&s, &d, 32, 10, None).unwrap();
    let r64 = render_reference(&s, &d, 8, 9, None).unwrap();
    assert!(
        mad(&r512, &r1024) < mad(&r64, &r1024),
        "{} vs {}",
        mad(&r512, &r1024),
        mad(&r64, &r1024)
    );
    assert!(render_reference_strata(&s, &d, [0, 4], 9, None).is_err());
    assert!(render_reference_strata(&s, &d, [4, 65], 9, None).is_err());
}

#[test]
fn reference_of_a_constant_texture_is_exact_with_coverage_fractions() {
    // A constant grey texture: covered pixels are exactly grey, background pixels exactly background,
    // and pixels on the horizon are in between.
    let (w, h) = (64, 36);
    let grey = Texture::from_fn(8, 8, Format::Rgba32Float, &Limits::default(), |_, _| {
        [0.25, 0.5, 0.75, 1.0]
    })
    .unwrap();
    let scene = Ground::with_texture(w, h, grey);
    let sampler = lab_sampler(4);
    let s = RenderSettings::new(w, h);
    let f = render_reference(&s, &[scene.draw(&sampler)], 4, 1, None).unwrap();
    let mut partial = 0;
    for (c, &cov) in f.color.iter().zip(&f.coverage()) {
        if !cov {
            assert_eq!(*c, [0.0, 0.0, 0.0, 1.0]);
        } else if c[1] < 0.4999 {
            // Partly covered: the colour is a coverage-weighted mean of grey and black.
            let a = c[1] / 0.5;
            assert!(
                (c[0] - 0.25 * a).abs() < 1e-5 && (c[2] - 0.75 * a).abs() < 1e-5,
                "{c:?}"
            );
            partial += 1;
        } else {
            assert!(
                (c[0] - 0.25).abs() < 1e-6 && (c[2] - 0.75).abs() < 1e-6,
                "{c:?}"
            );
        }
    }
    assert!(partial > 0 && partial <= 2 * w as usize);
}

#[test]
fn reference_agrees_with_the_rasterizer_where_the_texture_is_magnified() {
    // With an 8x8 checker (one texel per check) the bottom of the ground scene is strongly
    // magnified: bilinear is smooth at the pixel scale, so the point-sampled bilinear render and
    // the box-filtered bilinear reference nearly agree there.
    let (w, h) = (160, 90);
    let scene = Ground::with_texture(w, h, common::checker(8, 8));
    let sampler = lab_sampler(2);
    let s = RenderSettings::new(w, h);
    let raster = render(&s, &[scene.draw(&sampler)]).unwrap();
    let calls = AtomicU64::new(0);
    let last = AtomicU64::new(0);
    let progress = |done: u64, total: u64| {
        calls.fetch_add(1, Ordering::Relaxed);
        last.fetch_max(done, Ordering::Relaxed);
        assert_eq!(total, u64::from(w * h));
    };
    let reference = render_reference(&s, &[scene.draw(&sampler)], 8, 5, Some(&progress)).unwrap();
    assert_eq!(calls.load(Ordering::Relaxed), 6); // 3 x 2 tiles of 64
    assert_eq!(last.load(Ordering::Relaxed), u64::from(w * h));
    let (mut sum, mut n) = (0.0, 0);
    for j in 75..90 {
        for i in 0..w {
            let k = raster.index(i, j);
            sum += f64::from((raster.color[k][0] - reference.color[k][0]).abs());
            n += 1;
        }
    }
    assert!(sum / f64::from(n) < 0.01, "{}", sum / f64::from(n));
    // Coverage of the reference includes the rasterizer's.
    assert!(raster
        .coverage()
        .iter()
        .zip(&reference.coverage())
        .all(|(&r, &f)| !r || f));
}

/// Two triangles meeting on a vertical edge at x = 64.3, just past the first tile's last pixel
/// centre: every sub-sample of every pixel hits one of them, so the reference of a white texture is
/// exactly white everywhere (binned by the pixel-centre box instead of the sample box, column 64's
/// left samples would see the background).
/// A triangle smaller than a pixel, covering no pixel centre, still shows as partial coverage.
#[test]
fn reference_covers_tile_seams_and_subpixel_triangles() {
    let (w, h) = (128u32, 72u32);
    let (tex, sampler) = white();
    let v = |x: f64, y: f64| screen_vertex(x, y, w, h);
    // The outer edges lie beyond the frame, so only the seam is an edge inside it.
    let vertices = vec![
        v(-2.0, -2.0),
        v(64.3, -2.0),
        v(64.3, 74.0),
        v(-2.0, 74.0),
        v(130.0, -2.0),
        v(130.0, 74.0),
    ];
    let triangles = [[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]];
    let draw = texel_raster::DrawCall {
        vertices: &vertices,
        triangles: &triangles,
        texture: &tex,
        sampler: &sampler,
        clip_from_world: glam::Mat4::IDENTITY,
        material: None,
        uv_mapping: None,
    };
    let s = RenderSettings::new(w, h);
    let f = render_reference(&s, &[draw], 4, 7, None).unwrap();
    assert_eq!(f.covered_pixels(), (w * h) as usize);
    for (k, c) in f.color.iter().enumerate() {
        assert_eq!(*c, [1.0; 4], "pixel ({}, {})", k as u32 % w, k as u32 / w);
    }

    // A 0.4 x 0.4 pixel triangle inside pixel (10, 10), away from its centre (10.5, 10.5).
    let tiny = vec![v(10.05, 10.05), v(10.45, 10.05), v(10.05, 10.45)];
    let draw = texel_raster::DrawCall {
        vertices: &tiny,
        triangles: &[[0, 1, 2]],
        texture: &tex,
        sampler: &sampler,
        clip_from_world: glam::Mat4::IDENTITY,
        material: None,
        uv_mapping: None,
    };
    assert_eq!(render(&s, &[draw]).unwrap().covered_pixels(), 0);
    let f = render_reference(&s, &[draw], 8, 7, None).unwrap();
    let k = (10 * w + 10) as usize;
    assert!(f.covered(k));
    // Background black, triangle white: the pixel's grey is the covered fraction (area 0.08).
    assert!(
        f.color[k][0] > 0.02 && f.color[k][0] < 0.2,
        "{:?}",
        f.color[k]
    );
    assert_eq!(f.covered_pixels(), 1);
}
