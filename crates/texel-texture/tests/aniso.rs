//! The anisotropic filters: hardware-style N x, EWA, ripmap, summed-area table.
//!
//! Run `cargo test --release -p texel-texture --test aniso -- --nocapture` to see the measured
//! numbers that the module docs of `ewa.rs` record.

use glam::{DVec2, Vec2};
use proptest::prelude::*;
use texel_texture::technique::ewa::Ellipse;
use texel_texture::{
    Address, AddressMode, BorderColor, Filter, FilterMode, Footprint, Format, Limits, Sampler,
    SamplerDescriptor, Texture, TextureError,
};

/// Deterministic uniform noise in [0, 1): the project's one generator.
use texel_texture::base::rng::SplitMix64 as Rng;

fn noise_texture(w: u32, h: u32, format: Format, seed: u64) -> Texture {
    let mut rng = Rng::new(seed);
    let texels: Vec<[f32; 4]> = (0..w * h)
        .map(|_| [rng.next_f32(), rng.next_f32(), rng.next_f32(), 1.0])
        .collect();
    Texture::from_fn(w, h, format, &Limits::default(), |i, j| {
        texels[(j * w + i) as usize]
    })
    .unwrap()
}

/// Every anisotropic minification technique, plus trilinear as the baseline.
fn technique(name: &str) -> SamplerDescriptor {
    match name {
        "trilinear" => SamplerDescriptor::from(Filter::Trilinear),
        "aniso2" => SamplerDescriptor::from(Filter::Aniso2),
        "aniso4" => SamplerDescriptor::from(Filter::Aniso4),
        "aniso8" => SamplerDescriptor::from(Filter::Aniso8),
        "aniso16" => SamplerDescriptor::from(Filter::Aniso16),
        "ewa" => SamplerDescriptor::minification(FilterMode::Ewa),
        "ewa-probes" => SamplerDescriptor::minification(FilterMode::EwaProbes),
        "ripmap" => SamplerDescriptor::minification(FilterMode::Ripmap),
        "sat" => SamplerDescriptor::minification(FilterMode::SummedArea),
        _ => unreachable!("unknown technique {name}"),
    }
}

const TECHNIQUES: [&str; 9] = [
    "trilinear",
    "aniso2",
    "aniso4",
    "aniso8",
    "aniso16",
    "ewa",
    "ewa-probes",
    "ripmap",
    "sat",
];

fn sampler(name: &str, mode: AddressMode) -> Sampler {
    Sampler::new(technique(name).with_address_mode(mode)).unwrap()
}

/// A footprint from its two screen axes in texels of level 0 of a `w x h` texture.
fn footprint(u: f32, v: f32, px: Vec2, py: Vec2, w: u32, h: u32) -> Footprint {
    let (w, h) = (w as f32, h as f32);
    Footprint {
        u,
        v,
        dudx: px.x / w,
        dvdx: px.y / h,
        dudy: py.x / w,
        dvdy: py.y / h,
    }
}

/// Axes of an ellipse: major `len * ratio` at `angle`, minor `len` perpendicular (texels).
fn axes(len: f32, ratio: f32, angle: f32) -> (Vec2, Vec2) {
    let d = Vec2::new(angle.cos(), angle.sin());
    (d * len * ratio, d.perp() * len)
}

// ---------------------------------------------------------------------------------------------
// Constant textures stay constant.

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn constant_texture_is_constant_under_every_filter(
        code in 0u8..=255,
        float in any::<bool>(),
        u in -2.0f32..3.0, v in -2.0f32..3.0,
        len in 0.01f32..40.0, ratio in 1.0f32..100.0, angle in 0.0f32..6.3,
        mode in prop::sample::select(vec![AddressMode::Repeat, AddressMode::MirrorRepeat,
                                          AddressMode::ClampToEdge, AddressMode::MirrorClampToEdge]),
    ) {
        let (w, h) = (37, 23); // odd sizes: fractional box weights in every reduction
        let c = f32::from(code) / 255.0;
        let format = if float { Format::Rgba32Float } else { Format::Rgba8Unorm };
        let tex = Texture::from_fn(w, h, format, &Limits::default(), |_, _| [c, c, c, 1.0]).unwrap();
        let (px, py) = axes(len, ratio, angle);
        let fp = footprint(u, v, px, py, w, h);
        for name in TECHNIQUES {
            let s = sampler(name, mode);
            let got = s.sample(&tex, &fp);
            for (k, want) in [c, c, c, 1.0].into_iter().enumerate() {
                prop_assert!((got[k] - want).abs() <= 1e-5 * want.max(1e-3),
                    "{name} {mode:?} channel {k}: {} != {want}", got[k]);
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Anisotropic N x with an isotropic footprint is trilinear, bit for bit.

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn anisotropic_isotropic_footprint_is_trilinear_bit_for_bit(
        u in -1.0f32..2.0, v in -1.0f32..2.0,
        len in 0.1f32..300.0, angle in 0.0f32..6.3, axis_aligned in any::<bool>(),
        bias in -1.0f32..1.0,
    ) {
        let tex = noise_texture(64, 64, Format::Rgba8Srgb, 7);
        let angle = if axis_aligned { 0.0 } else { angle };
        let (px, py) = axes(len, 1.0, angle);
        let fp = footprint(u, v, px, py, 64, 64);
        let tri = Sampler::new(SamplerDescriptor { lod_bias: bias, ..technique("trilinear") }
            .with_address_mode(AddressMode::Repeat)).unwrap();
        let (want, want_reads) = tri.sample_counted(&tex, &fp);
        for mode in 5..=8 {
            let desc = SamplerDescriptor { lod_bias: bias, ..Filter::from_lab_mode(mode).map(SamplerDescriptor::from).unwrap() };
            let s = Sampler::new(desc.with_address_mode(AddressMode::Repeat)).unwrap();
            let (got, reads) = s.sample_counted(&tex, &fp);
            prop_assert_eq!(got.map(f32::to_bits), want.map(f32::to_bits), "mode {}", mode);
            prop_assert_eq!(reads, want_reads);
        }
    }
}

#[test]
fn anisotropic_probe_counts_follow_the_ext_rule() {
    let tex = noise_texture(256, 256, Format::Rgba8Unorm, 3);
    // Major 32 texels along u, minor 8: ratio 4 -> 4 probes at lod log2(32 / 4) = 3 (integer:
    // one level per probe, 4 texels each).
    let fp = footprint(
        0.5,
        0.5,
        Vec2::new(32.0, 0.0),
        Vec2::new(0.0, 8.0),
        256,
        256,
    );
    for (mode, probes) in [(5u8, 2u32), (6, 4), (7, 4), (8, 4)] {
        let s = Sampler::new(
            Filter::from_lab_mode(mode)
                .map(SamplerDescriptor::from)
                .unwrap(),
        )
        .unwrap();
        let (_, reads) = s.sample_counted(&tex, &fp);
        // 2 probes at lod log2(16) = 4 are also integer lods.
        assert_eq!(reads, 4 * probes, "mode {mode}");
    }
    // The probes average trilinear lookups spaced |Pmax| / N along the major axis.
    let s = Sampler::new(SamplerDescriptor::from(Filter::Aniso4)).unwrap();
    let tri = Sampler::new(SamplerDescriptor::from(Filter::Trilinear)).unwrap();
    let got = s.sample(&tex, &fp);
    let mut want = [0.0f32; 4];
    for i in 0..4 {
        let t = (i as f32 + 0.5) / 4.0 - 0.5;
        let probe = Footprint::isotropic(0.5 + t * 32.0 / 256.0, 0.5, 8.0 / 256.0);
        let c = tri.sample(&tex, &probe);
        for k in 0..4 {
            want[k] += c[k] / 4.0;
        }
    }
    for k in 0..4 {
        assert!((got[k] - want[k]).abs() < 1e-6, "{got:?} vs {want:?}");
    }
}

// ---------------------------------------------------------------------------------------------
// EWA: normalised weights, rotation invariance.

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// The raw weights are the table's: each lies in `(0, LUT[0]]`, and a texel centre at the
    /// ellipse's centre gets the largest one, `LUT[0] = 1 - e^-2`. (That EWA divides by their sum
    /// is what `constant_texture_is_constant_under_every_filter` checks.)
    #[test]
    fn ewa_weights_come_from_the_table(
        px in prop::array::uniform2(-50.0f32..50.0), py in prop::array::uniform2(-50.0f32..50.0),
        x in -100.0f32..100.0, y in -100.0f32..100.0, scale in 0.01f64..1.0,
    ) {
        let lut = texel_texture::technique::ewa::weight_lut();
        let e = Ellipse::from_axes(Vec2::from(px), Vec2::from(py), 16.0).unwrap();
        let q = e.in_level(DVec2::splat(scale), true);
        let mut weights = Vec::new();
        q.scan(x, y, |line| weights.extend(line.weights().filter(|&w| w > 0.0)));
        prop_assert!(!weights.is_empty());
        prop_assert!(weights.iter().all(|&w| w > 0.0 && w <= lut[0]));
        prop_assert!(weights.iter().all(|w| lut.contains(w)));
        // The quadratic form at the centre is 0, so any texel centre within r^2 < 1/128 of it gets
        // LUT[0]; the ellipse always covers at least the circle of radius sqrt(KERNEL_SCALE) =
        // 0.78 > sqrt(1/2) (Q = KERNEL_SCALE (D (S + I) D + I)), so some texel centre.
        let (fx, fy) = (x - x.floor() - 0.5, y - y.floor() - 0.5);
        if fx * fx + fy * fy < 1e-4 {
            prop_assert!(weights.contains(&lut[0]));
        }
    }
}

/// At a texel centre the centre texel gets `LUT[0]`, the largest weight, for any ellipse.
#[test]
fn ewa_centre_texel_gets_the_peak_weight() {
    let lut = texel_texture::technique::ewa::weight_lut();
    for (px, py) in [
        ((3.0, 0.0), (0.0, 1.0)),
        ((5.0, 5.0), (-0.5, 0.5)),
        ((0.2, 0.0), (0.0, 0.2)),
    ] {
        let e = Ellipse::from_axes(Vec2::from(px), Vec2::from(py), 16.0).unwrap();
        let q = e.in_level(DVec2::ONE, true);
        let mut centre = None;
        q.scan(10.5, 20.5, |line| {
            for (k, w) in line.weights().enumerate() {
                if line.texel(k) == (10, 20) {
                    centre = Some(w);
                }
            }
        });
        assert_eq!(centre, Some(lut[0]), "{px:?} {py:?}");
    }
}

#[test]
fn ewa_circular_footprint_is_rotation_invariant() {
    // A radially symmetric texture equals itself rotated by 30 degrees about its centre, so
    // sampling the rotated texture at p is sampling this one at R(30) p, with the footprint's
    // axes rotated too: a circular EWA footprint must give the same value. "Within 1 %" is the
    // RMS relative difference over 200 random points and radii; single points differ by up to
    // about 1.5 % (EWA's discrete kernel at the coarse level holds only a few texels, so its
    // effective blur varies with the sub-texel position; trilinear shows the same effect). The
    // worst case is bounded at 4 %.
    let n = 256u32;
    let c = n as f32 / 2.0;
    let tex = Texture::from_fn(n, n, Format::Rgba32Float, &Limits::default(), |i, j| {
        let r = Vec2::new(i as f32 + 0.5 - c, j as f32 + 0.5 - c).length();
        let f = 0.5 + 0.3 * (std::f32::consts::TAU * r / 64.0).cos();
        [f, f, f, 1.0]
    })
    .unwrap();
    let rot = glam::Mat2::from_angle(30f32.to_radians());
    let measure = |s: &Sampler| {
        let mut rng = Rng::new(11);
        let (mut worst, mut sum2) = (0.0f32, 0.0f32);
        for _ in 0..200 {
            let p = Vec2::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5) * 120.0;
            let radius = 1.5 + 4.0 * rng.next_f32();
            let (px, py) = axes(radius, 1.0, rng.next_f32() * 6.3);
            let at = |p: Vec2, px: Vec2, py: Vec2| {
                let uv = (p + Vec2::splat(c)) / n as f32;
                s.sample(&tex, &footprint(uv.x, uv.y, px, py, n, n))[0]
            };
            let a = at(p, px, py);
            let b = at(rot * p, rot * px, rot * py);
            let e = (a - b).abs() / a;
            worst = worst.max(e);
            sum2 += e * e;
        }
        ((sum2 / 200.0).sqrt(), worst)
    };
    let (rms, worst) = measure(&sampler("ewa", AddressMode::ClampToEdge));
    let (tri_rms, tri_worst) = measure(&sampler("trilinear", AddressMode::ClampToEdge));
    println!(
        "rotation by 30 degrees, relative difference: EWA RMS {rms:.4} worst {worst:.4}; \
         trilinear RMS {tri_rms:.4} worst {tri_worst:.4}"
    );
    assert!(rms <= 0.01, "EWA RMS relative difference {rms}");
    assert!(worst <= 0.04, "EWA worst relative difference {worst}");
}

// ---------------------------------------------------------------------------------------------
// Summed-area table against brute force.

/// Brute-force mean of the texture over `[x0, x1) x [y0, y1)` with the address modes (f64).
fn brute_box_mean(
    tex: &Texture,
    (x0, y0, x1, y1): (f64, f64, f64, f64),
    mu: AddressMode,
    mv: AddressMode,
    border: [f32; 4],
) -> [f64; 4] {
    let (w, h) = (tex.width(), tex.height());
    let mut sum = [0.0f64; 4];
    let overlap = |k: i64, a: f64, b: f64| (b.min(k as f64 + 1.0) - a.max(k as f64)).max(0.0);
    for j in (y0.floor() as i64)..(y1.ceil() as i64) {
        let wy = overlap(j, y0, y1);
        for i in (x0.floor() as i64)..(x1.ceil() as i64) {
            let wt = overlap(i, x0, x1) * wy;
            let t = match (mu.wrap(i, w), mv.wrap(j, h)) {
                (Some(i), Some(j)) => tex.texel(0, i, j).unwrap(),
                _ => border,
            };
            for c in 0..4 {
                sum[c] += wt * f64::from(t[c]);
            }
        }
    }
    let area = (x1 - x0) * (y1 - y0);
    sum.map(|s| s / area)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn summed_area_box_mean_equals_brute_force(
        x0 in -30.0f64..40.0, y0 in -20.0f64..30.0,
        bw in 0.01f64..30.0, bh in 0.01f64..20.0,
        integer in any::<bool>(),
        mu in prop::sample::select(vec![AddressMode::Repeat, AddressMode::MirrorRepeat,
            AddressMode::ClampToEdge, AddressMode::ClampToBorder, AddressMode::MirrorClampToEdge]),
        mv in prop::sample::select(vec![AddressMode::Repeat, AddressMode::MirrorRepeat,
            AddressMode::ClampToEdge, AddressMode::ClampToBorder, AddressMode::MirrorClampToEdge]),
        srgb in any::<bool>(),
    ) {
        // Texels in [0.1, 1] so that "relative" is meaningful; the border is white.
        let format = if srgb { Format::Rgba8Srgb } else { Format::Rgba32Float };
        let mut rng = Rng::new(5);
        let vals: Vec<f32> = (0..13 * 7 * 3).map(|_| 0.1 + 0.9 * rng.next_f32()).collect();
        let tex = Texture::from_fn(13, 7, format, &Limits::default(), |i, j| {
            let k = ((j * 13 + i) * 3) as usize;
            [vals[k], vals[k + 1], vals[k + 2], 1.0]
        }).unwrap();
        let (x0, y0, bw, bh) = if integer {
            (x0.floor(), y0.floor(), bw.ceil(), bh.ceil())
        } else {
            (x0, y0, bw, bh)
        };
        let rect = (x0, y0, x0 + bw, y0 + bh);
        let table = tex.summed_area_table().unwrap();
        let got = table.box_mean([rect.0, rect.2], [rect.1, rect.3], &Address::new(mu, mv, BorderColor::OpaqueWhite));
        let want = brute_box_mean(&tex, rect, mu, mv, [1.0; 4]);
        for c in 0..4 {
            prop_assert!((got[c] - want[c]).abs() <= 1e-6 * want[c].abs(),
                "{mu:?}/{mv:?} {rect:?} channel {c}: {} vs {}", got[c], want[c]);
        }
    }
}

#[test]
fn summed_area_repeat_across_the_edge() {
    let tex = noise_texture(16, 16, Format::Rgba32Float, 9);
    let t = tex.summed_area_table().unwrap();
    let r = AddressMode::Repeat;
    for rect in [
        (14.0, 3.0, 18.0, 5.0),           // integer, across the right edge
        (14.25, -1.5, 17.75, 2.5),        // fractional, across two edges
        (-40.3, -33.1, 3.7, 0.2),         // several whole periods
        (1e5 + 0.5, 2.0, 1e5 + 1.5, 3.0), // far away
    ] {
        let got = t.box_mean(
            [rect.0, rect.2],
            [rect.1, rect.3],
            &Address::new(r, r, BorderColor::TransparentBlack),
        );
        let want = brute_box_mean(&tex, rect, r, r, [0.0; 4]);
        for c in 0..3 {
            assert!(
                (got[c] - want[c]).abs() <= 1e-6 * want[c].abs(),
                "{rect:?}: {got:?} vs {want:?}"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Ripmap and summed-area table: sharper on axis-aligned footprints, blur (not alias) at 45 deg.

/// Contrast (max - min of the red channel) over samples across `v` at fixed `u`.
fn contrast_along_v(s: &Sampler, tex: &Texture, u: f32, px: Vec2, py: Vec2) -> f32 {
    let (w, h) = (tex.width(), tex.height());
    let vals: Vec<f32> = (0..64)
        .map(|k| {
            let v = (k as f32 + 0.5) / 64.0 * 0.25;
            s.sample(tex, &footprint(u, v, px, py, w, h))[0]
        })
        .collect();
    let max = vals.iter().cloned().fold(f32::MIN, f32::max);
    let min = vals.iter().cloned().fold(f32::MAX, f32::min);
    max - min
}

#[test]
fn ripmap_and_sat_are_sharper_than_trilinear_on_axis_aligned_footprints() {
    // Checks 64 texels wide (u) and 4 tall (v): resolvable along v, the minor axis below.
    let tex = Texture::from_fn(256, 256, Format::Rgba8Unorm, &Limits::default(), |i, j| {
        let c = ((i / 64 + j / 4) % 2) as f32;
        [c, c, c, 1.0]
    })
    .unwrap();
    // Major 32 texels along u, minor 2 along v; u at the centre of a check column.
    let (px, py) = (Vec2::new(32.0, 0.0), Vec2::new(0.0, 2.0));
    let u = 32.0 / 256.0;
    let mut c = std::collections::BTreeMap::new();
    for name in ["trilinear", "aniso16", "ewa", "ripmap", "sat"] {
        let s = sampler(name, AddressMode::Repeat);
        c.insert(name, contrast_along_v(&s, &tex, u, px, py));
    }
    println!("contrast on 64x4 checks, 32:2 footprint: {c:?}");
    assert!(
        c["trilinear"] < 0.05,
        "trilinear blurs the checks away: {c:?}"
    );
    assert!(c["ripmap"] > 0.5, "{c:?}");
    assert!(c["sat"] > 0.5, "{c:?}");
}

#[test]
fn ripmap_and_sat_blur_not_alias_at_45_degrees() {
    // A fine checkerboard (2-texel checks) under a 16:1 footprint at 45 degrees: the ripmap and
    // the summed-area table use a square box as long as the major axis, so they return nearly the
    // mean everywhere (blur); a level-0 bilinear lookup shows the false full-contrast pattern
    // (alias) that they must not.
    let n = 256;
    let tex = Texture::from_fn(n, n, Format::Rgba8Unorm, &Limits::default(), |i, j| {
        let c = ((i / 2 + j / 2) % 2) as f32;
        [c, c, c, 1.0]
    })
    .unwrap();
    let (px, py) = axes(2.0, 16.0, std::f32::consts::FRAC_PI_4);
    let spread = |s: &Sampler| {
        let mut rng = Rng::new(21);
        let mut dev = 0.0f32;
        for _ in 0..200 {
            let (u, v) = (rng.next_f32(), rng.next_f32());
            let c = s.sample(&tex, &footprint(u, v, px, py, n, n))[0];
            dev = dev.max((c - 0.5).abs());
        }
        dev
    };
    let bilinear = Sampler::new(SamplerDescriptor::from(Filter::Bilinear)).unwrap();
    let alias = spread(&bilinear);
    assert!(
        alias > 0.4,
        "the test texture aliases without prefiltering: {alias}"
    );
    for name in ["ripmap", "sat", "trilinear"] {
        let d = spread(&sampler(name, AddressMode::Repeat));
        println!("45-degree 16:1 footprint, max |c - mean|: {name} {d:.4} (bilinear {alias:.4})");
        assert!(d < 0.1, "{name} must blur, not alias: {d}");
    }
}

// ---------------------------------------------------------------------------------------------
// Against a brute-force Gaussian over the ellipse.

/// Brute-force Gaussian-weighted mean of level 0 over the kernel's ellipse for conjugate
/// semi-diameters `px`, `py` (texels): the covariance `(M M^T + 2 I) / 12` of the pixel box and
/// the bilinear tent, written out from the derivation (`r^2 = d^T Q0^{-1} d` with
/// `Q0 = (M M^T + 2 I) / (12 v)`, `v` the weight's second moment on the unit disc integrated
/// numerically here), weight `exp(-2 r^2) - exp(-2)` for `r^2 < 1`; Repeat. No level, no scan,
/// no table.
fn brute_gaussian(tex: &Texture, x: f64, y: f64, px: Vec2, py: Vec2) -> [f64; 3] {
    let (px, py) = (px.as_dvec2(), py.as_dvec2());
    let scale = 1.0 / (12.0 * disc_second_moment());
    let q00 = scale * (px.x * px.x + py.x * py.x + 2.0);
    let q01 = scale * (px.x * px.y + py.x * py.y);
    let q11 = scale * (px.y * px.y + py.y * py.y + 2.0);
    let det = q00 * q11 - q01 * q01;
    let (rx, ry) = (q00.sqrt().ceil() as i64 + 1, q11.sqrt().ceil() as i64 + 1);
    let (w, h) = (tex.width(), tex.height());
    let mut sum = [0.0f64; 3];
    let mut wsum = 0.0;
    for j in (y.floor() as i64 - ry)..=(y.floor() as i64 + ry) {
        for i in (x.floor() as i64 - rx)..=(x.floor() as i64 + rx) {
            let dx = i as f64 + 0.5 - x;
            let dy = j as f64 + 0.5 - y;
            let r2 = (q11 * dx * dx - 2.0 * q01 * dx * dy + q00 * dy * dy) / det;
            if r2 < 1.0 {
                let wt = (-2.0 * r2).exp() - (-2.0f64).exp();
                let t = tex
                    .texel(
                        0,
                        i.rem_euclid(i64::from(w)) as u32,
                        j.rem_euclid(i64::from(h)) as u32,
                    )
                    .unwrap();
                for c in 0..3 {
                    sum[c] += wt * f64::from(t[c]);
                }
                wsum += wt;
            }
        }
    }
    sum.map(|s| s / wsum)
}

/// Per-axis second moment of `exp(-2 r^2) - exp(-2)` on the unit disc: `(1/2) E[r^2]` by the
/// midpoint rule in `r` (weight `r dr`).
fn disc_second_moment() -> f64 {
    let n = 200_000;
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..n {
        let r = (i as f64 + 0.5) / n as f64;
        let w = (-2.0 * r * r).exp() - (-2.0f64).exp();
        num += 0.5 * r * r * w * r;
        den += w * r;
    }
    num / den
}

/// The kernel's constants are its derivation's: the closed-form second moment equals the
/// numerical integral, and `KERNEL_SCALE = 1 / (12 v)`.
#[test]
fn ewa_kernel_constants_follow_from_the_weight() {
    use texel_texture::technique::ewa::{kernel_variance, KERNEL_SCALE};
    let v = disc_second_moment();
    assert!(
        (kernel_variance() - v).abs() < 1e-9,
        "{} vs {v}",
        kernel_variance()
    );
    assert!((KERNEL_SCALE - 1.0 / (12.0 * kernel_variance())).abs() < 1e-15);
}

/// The weights EWA puts on a level's texel centres have the covariance of the pixel box carried
/// through the Jacobian plus level 0's bilinear tent, `(S + 2 I) / 12` on level 0, and
/// `(D (S + I) D + I) / 12` on level 2, for footprints of 16 to 80 level-0 texels at any angle:
/// within 1 % on level 0 and 3 % on level 2, where the kernel covers about 60 texel centres (the
/// sum over texel centres approximates the integral, and the table rounds `r^2` down).
#[test]
fn ewa_weights_have_the_pixel_boxs_covariance() {
    let lut = texel_texture::technique::ewa::weight_lut();
    let mut rng = Rng::new(7);
    let mut worst = [0.0f64; 2];
    for _ in 0..50 {
        let minor = 16.0 + 24.0 * rng.next_f32();
        let ratio = 1.0 + 1.0 * rng.next_f32();
        let (px, py) = axes(minor, ratio, rng.next_f32() * std::f32::consts::TAU);
        let e = Ellipse::from_axes(px, py, 16.0).unwrap();
        let d = if rng.next_f32() < 0.5 { 1.0 } else { 0.25 };
        let q = e.in_level(DVec2::splat(d), false);
        let (x, y) = (100.0 + rng.next_f32(), 100.0 + rng.next_f32());
        let (mut w, mut sxx, mut sxy, mut syy) = (0.0f64, 0.0, 0.0, 0.0);
        q.scan(x, y, |line| {
            for (k, wt) in line.weights().enumerate() {
                let (i, j) = line.texel(k);
                let dx = i as f64 + 0.5 - f64::from(x);
                let dy = j as f64 + 0.5 - f64::from(y);
                let wt = f64::from(wt);
                w += wt;
                sxx += wt * dx * dx;
                sxy += wt * dx * dy;
                syy += wt * dy * dy;
            }
        });
        assert!(lut[0] > 0.0 && w > 0.0);
        let d2 = d * d;
        let want = [
            (d2 * (e.s00 + 1.0) + 1.0) / 12.0,
            d2 * e.s01 / 12.0,
            (d2 * (e.s11 + 1.0) + 1.0) / 12.0,
        ];
        let got = [sxx / w, sxy / w, syy / w];
        let scale = want[0].max(want[2]);
        let err = (0..3)
            .map(|c| (got[c] - want[c]).abs() / scale)
            .fold(0.0, f64::max);
        let (slot, bound) = if d == 1.0 { (0, 0.01) } else { (1, 0.03) };
        worst[slot] = worst[slot].max(err);
        assert!(
            err < bound,
            "{got:?} vs {want:?} ({px}, {py}), level scale {d}"
        );
    }
    println!(
        "covariance's largest relative error: level 0 {:.4}, level 2 {:.4}",
        worst[0], worst[1]
    );
}

#[test]
fn ewa_and_aniso_beat_trilinear_against_brute_force_gaussian() {
    let n = 256;
    let tex = noise_texture(n, n, Format::Rgba32Float, 1234);
    let names = ["trilinear", "aniso16", "ewa", "ewa-probes"];
    let samplers: Vec<Sampler> = names
        .iter()
        .map(|name| sampler(name, AddressMode::Repeat))
        .collect();
    let mut err2 = [0.0f64; 4];
    let mut reads = [0u64; 4];
    let mut rng = Rng::new(99);
    let count = 300;
    for _ in 0..count {
        let (u, v) = (rng.next_f32(), rng.next_f32());
        let minor = 1.5 + 4.5 * rng.next_f32();
        let ratio = 1.0 + 15.0 * rng.next_f32();
        let (px, py) = axes(minor, ratio, rng.next_f32() * std::f32::consts::TAU);
        let fp = footprint(u, v, px, py, n, n);
        let want = brute_gaussian(
            &tex,
            f64::from(u * n as f32),
            f64::from(v * n as f32),
            px,
            py,
        );
        for (k, s) in samplers.iter().enumerate() {
            let (got, r) = s.sample_counted(&tex, &fp);
            reads[k] += u64::from(r);
            for c in 0..3 {
                err2[k] += (f64::from(got[c]) - want[c]).powi(2);
            }
        }
    }
    let rms: Vec<f64> = err2
        .iter()
        .map(|e| (e / (3 * count) as f64).sqrt())
        .collect();
    for k in 0..4 {
        println!(
            "{:>10}: RMS error {:.4}, texels read per sample {:.1}",
            names[k],
            rms[k],
            reads[k] as f64 / count as f64
        );
    }
    assert!(
        rms[1] < rms[0],
        "aniso16 {} vs trilinear {}",
        rms[1],
        rms[0]
    );
    assert!(rms[2] < rms[0], "EWA {} vs trilinear {}", rms[2], rms[0]);
    assert!(rms[2] < rms[1], "EWA {} vs aniso16 {}", rms[2], rms[1]);
    assert!(
        rms[3] < rms[1],
        "EWA from probes {} vs aniso16 {}",
        rms[3],
        rms[1]
    );
}

/// EWA from probes puts the reference's covariance `C = (S + 2 I) / 12` on its probes: the
/// weighted positions' covariance plus one trilinear probe's variance at the matched lod (the
/// plan's lod less `LOD_OFFSET`) is `C` (exact, up to rounding), for footprints of 1 to 40
/// texels, ratios 1 to 16, any angle. Where the probes run out, the probes' kernel has grown:
/// the major axis still carries `lambda_1`, the minor axis more than `lambda_2`.
#[test]
fn ewa_probes_carry_the_reference_covariance() {
    use texel_texture::technique::ewa_probes::{
        plan, probe_table, variance_of_lod, LOD_OFFSET, MAX_PROBES,
    };
    let table = probe_table();
    let mut rng = Rng::new(31);
    let (mut capped, mut exact) = (0, 0);
    for _ in 0..2000 {
        let minor = 1.0 + 39.0 * rng.next_f32();
        let ratio = 1.0 + 15.0 * rng.next_f32();
        let (px, py) = axes(minor, ratio, rng.next_f32() * std::f32::consts::TAU);
        let size = (512, 256);
        let e = Ellipse::from_axes(px, py, 16.0).unwrap();
        let c = [(e.s00 + 2.0) / 12.0, e.s01 / 12.0, (e.s11 + 2.0) / 12.0];
        let pl = plan(px, py, size, 16.0).unwrap();
        let probe = variance_of_lod(pl.lod - LOD_OFFSET);
        let a = pl.axis_texels;
        let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
        for i in 0..pl.n {
            let (w, t) = (
                f64::from(table.weights[pl.n - 1][i]),
                f64::from(table.positions[pl.n - 1][i]),
            );
            xx += w * t * t * a.x * a.x;
            xy += w * t * t * a.x * a.y;
            yy += w * t * t * a.y * a.y;
        }
        let got = [xx + probe, xy, yy + probe];
        let scale = c[0].max(c[2]);
        let l1 = (e.major * e.major + 2.0) / 12.0;
        let l2 = (e.minor * e.minor + 2.0) / 12.0;
        // The uv axis is the texel axis over the level's size.
        assert!((pl.axis_uv.x * 512.0 - a.x).abs() <= 1e-9 * a.length().max(1.0));
        assert!((pl.axis_uv.y * 256.0 - a.y).abs() <= 1e-9 * a.length().max(1.0));
        if pl.n == 1 {
            // A near-circle: one probe with the minor variance, within `ONE_PROBE` of `C`.
            assert!(l1 <= 1.1 * l2 + 1e-12 && (probe - l2).abs() < 1e-9 * l2);
            continue;
        }
        if pl.n == MAX_PROBES && probe > l2 * (1.0 + 1e-9) {
            capped += 1;
            // Along the major axis the total is lambda_1; across, the grown probe variance.
            let major = (got[0] * a.x * a.x + 2.0 * got[1] * a.x * a.y + got[2] * a.y * a.y)
                / a.length_squared();
            assert!((major - l1).abs() < 1e-6 * l1, "{major} vs {l1}");
            continue;
        }
        exact += 1;
        let err = (0..3)
            .map(|k| (got[k] - c[k]).abs() / scale)
            .fold(0.0, f64::max);
        assert!(err < 1e-5, "{got:?} vs {c:?} ({px}, {py}), {} probes", pl.n);
    }
    println!("EWA from probes: {exact} footprints matched exactly, {capped} at the probe limit");
    assert!(exact > 1000 && capped > 10, "{exact} {capped}");
}

// ---------------------------------------------------------------------------------------------
// Degenerate footprints, structures, validation.

#[test]
fn degenerate_footprints_never_panic_and_stay_bounded() {
    let texs = [
        noise_texture(33, 17, Format::Rgba8Srgb, 4),
        noise_texture(1, 1, Format::Rgba32Float, 5),
        noise_texture(64, 1, Format::Rgba8Unorm, 6),
    ];
    let big = [
        0.0,
        1e-30,
        1.0,
        1e6,
        1e30,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
    ];
    let mut fps = Vec::new();
    for &a in &big {
        for &b in &[0.0f32, 1e-6, 1.0, f32::NAN] {
            fps.push(Footprint {
                u: 0.3,
                v: 0.6,
                dudx: a,
                dudy: 0.0,
                dvdx: 0.0,
                dvdy: b,
            });
            fps.push(Footprint {
                u: 0.3,
                v: 0.6,
                dudx: a,
                dudy: b,
                dvdx: a,
                dvdy: b,
            });
        }
    }
    // 1e6 : 1 at several angles.
    for k in 0..8 {
        let (px, py) = axes(1e-6, 1e6, k as f32 * 0.4);
        fps.push(footprint(0.5, 0.5, px, py, 1, 1));
    }
    for (u, v) in [
        (f32::NAN, 0.5),
        (f32::INFINITY, -1e9),
        (1e9, 1e9),
        (-3.5, 7.25),
    ] {
        fps.push(Footprint {
            u,
            v,
            dudx: 0.2,
            dudy: 0.0,
            dvdx: 0.0,
            dvdy: 0.01,
        });
    }
    let modes = [
        AddressMode::Repeat,
        AddressMode::MirrorRepeat,
        AddressMode::ClampToEdge,
        AddressMode::ClampToBorder,
        AddressMode::MirrorClampToEdge,
    ];
    for tex in &texs {
        for name in TECHNIQUES {
            for mode in modes {
                let s = sampler(name, mode);
                for fp in &fps {
                    let (c, reads) = s.sample_counted(tex, fp);
                    // Bounded work: 16 trilinear probes, two EWA levels, 4 bilinear, 36 corners.
                    assert!(
                        reads <= 2 * texel_texture::technique::ewa::MAX_VISITS,
                        "{name} {fp:?}: {reads}"
                    );
                    let sane = fp.u.abs() < 1e8 && fp.v.abs() < 1e8;
                    if sane {
                        assert!(
                            c.iter().all(|x| x.is_finite()),
                            "{name} {mode:?} {fp:?}: {c:?}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn reads_are_counted_for_every_filter() {
    let tex = noise_texture(128, 128, Format::Rgba8Unorm, 8);
    tex.build_structures(&sampler("ripmap", AddressMode::Repeat))
        .unwrap();
    tex.build_structures(&sampler("sat", AddressMode::Repeat))
        .unwrap();
    let (px, py) = (Vec2::new(16.0, 0.0), Vec2::new(0.0, 4.0));
    let fp = footprint(0.37, 0.61, px, py, 128, 128);
    let reads = |name: &str| {
        sampler(name, AddressMode::Repeat)
            .sample_counted(&tex, &fp)
            .1
    };
    // Ripmap: lods (4, 2) exactly: one image, one bilinear lookup.
    assert_eq!(reads("ripmap"), 4);
    // SAT: a 16 x 4 box with fractional edges inside the texture: 4 corners x 4 entries.
    assert_eq!(reads("sat"), 16);
    // Anisotropic 16x: ratio 4 -> 4 probes at lod 2 (integer): 4 texels each.
    assert_eq!(reads("aniso16"), 16);
    // EWA: lod 2 (the minor semi-axis), one level, about the kernel's ellipse's area there.
    let e = reads("ewa");
    let area = Ellipse::from_axes(px, py, 16.0)
        .unwrap()
        .in_level(DVec2::splat(0.25), false)
        .area();
    assert!(
        f64::from(e) > 0.5 * area && f64::from(e) < 2.0 * area + 4.0,
        "EWA reads {e}, the ellipse covers {area:.1} texels"
    );
}

#[test]
fn structures_are_prepared_reported_and_limited() {
    fn assert_sync<T: Sync + Send>() {}
    assert_sync::<Texture>();
    let tex = noise_texture(64, 32, Format::Rgba8Unorm, 2);
    let desc = |f| SamplerDescriptor::minification(f);
    let pyramid = tex.pyramid_bytes();
    assert_eq!(tex.structure_bytes(&technique("aniso16")), pyramid);
    assert_eq!(tex.structure_bytes(&desc(FilterMode::Ewa)), pyramid);
    // Ripmap: (64+32+...+1)(32+...+1) - 64*32 texels of 4 bytes.
    assert_eq!(
        tex.structure_bytes(&desc(FilterMode::Ripmap)),
        pyramid + (127 * 63 - 64 * 32) * 4
    );
    assert_eq!(
        tex.structure_bytes(&desc(FilterMode::SummedArea)),
        pyramid + 65 * 33 * 32
    );
    let rip = Sampler::new(desc(FilterMode::Ripmap)).unwrap();
    tex.build_structures(&rip).unwrap();
    assert_eq!(tex.ripmap().unwrap().bytes(), (127 * 63 - 64 * 32) * 4);
    assert_eq!(tex.summed_area_table().unwrap().bytes(), 65 * 33 * 32);
    // A ripmap's build holds 40 bytes of f32 scratch per level-0 texel; nothing else builds any.
    assert_eq!(
        tex.build_scratch_bytes(&desc(FilterMode::Ripmap)),
        64 * 32 * 40
    );
    for f in [FilterMode::SummedArea, FilterMode::Ewa, FilterMode::Linear] {
        assert_eq!(tex.build_scratch_bytes(&desc(f)), 0, "{f:?}");
    }
    // A texture's build: the pyramid (64x32 down to 1x1: 2,730 texels of 4 bytes) and 16 bytes of
    // f32 scratch per texel below level 0; `check` admits exactly that many bytes.
    let texels = 64 * 32 + 32 * 16 + 16 * 8 + 8 * 4 + 4 * 2 + 2 + 1;
    assert_eq!(texels * 4, pyramid);
    let built = Limits::texture_bytes(64, 32, Format::Rgba8Unorm);
    assert_eq!(built, texels * 4 + (texels - 64 * 32) * 16);
    let at = |max_bytes| Limits {
        max_dimension: 16384,
        max_bytes,
    };
    assert!(at(built).check(64, 32, Format::Rgba8Unorm).is_ok());
    assert!(matches!(
        at(built - 1).check(64, 32, Format::Rgba8Unorm),
        Err(TextureError::OverMemoryLimit { bytes, .. }) if bytes == built
    ));
    assert_eq!(
        Limits::texture_bytes(u32::MAX, u32::MAX, Format::Rgba32Float),
        u64::MAX
    );

    // Over the limit: prepare reports it, sampling falls back to trilinear (no panic, no OOM).
    let limits = Limits {
        max_dimension: 16384,
        max_bytes: 48 * 1024,
    };
    let small = Texture::from_fn(64, 64, Format::Rgba8Unorm, &limits, |i, j| {
        [((i + j) % 2) as f32, 0.0, 0.0, 1.0]
    })
    .unwrap();
    let fp = footprint(0.5, 0.5, Vec2::new(8.0, 0.0), Vec2::new(0.0, 2.0), 64, 64);
    let tri = sampler("trilinear", AddressMode::ClampToEdge).sample(&small, &fp);
    for f in [FilterMode::Ripmap, FilterMode::SummedArea] {
        let s = Sampler::new(desc(f)).unwrap();
        assert!(matches!(
            small.build_structures(&s),
            Err(TextureError::StructureOverMemoryLimit { .. })
        ));
        assert_eq!(s.sample(&small, &fp), tri);
    }
}

#[test]
fn descriptor_validation() {
    for f in [FilterMode::Ewa, FilterMode::Ripmap, FilterMode::SummedArea] {
        let bad = SamplerDescriptor {
            mag_filter: f,
            ..SamplerDescriptor::minification(f)
        };
        assert!(matches!(
            Sampler::new(bad),
            Err(TextureError::MinificationOnlyFilter(g)) if g == f
        ));
    }
    let bad = SamplerDescriptor {
        min_filter: FilterMode::Nearest,
        ..SamplerDescriptor::anisotropic(8)
    };
    assert!(matches!(
        Sampler::new(bad),
        Err(TextureError::AnisotropyNeedsLinear(8))
    ));
    assert!(matches!(
        Sampler::new(SamplerDescriptor::anisotropic(65)),
        Err(TextureError::InvalidAnisotropyClamp(65))
    ));
    for (mode, n) in [(5u8, 2u16), (6, 4), (7, 8), (8, 16)] {
        let d = Filter::from_lab_mode(mode)
            .map(SamplerDescriptor::from)
            .unwrap();
        assert_eq!(d.anisotropy_clamp, n);
        assert_eq!(d.min_filter, FilterMode::Linear);
    }
    assert!(matches!(
        Filter::from_lab_mode(9),
        Err(TextureError::UnknownLabMode(9))
    ));
    // EWA with the WebGPU default clamp of 1 uses 16; an explicit 16 gives the same result.
    let tex = noise_texture(64, 64, Format::Rgba32Float, 3);
    let fp = footprint(0.4, 0.4, Vec2::new(40.0, 0.0), Vec2::new(0.0, 0.5), 64, 64);
    let one = Sampler::new(SamplerDescriptor {
        anisotropy_clamp: 1,
        ..SamplerDescriptor::minification(FilterMode::Ewa)
    })
    .unwrap();
    let sixteen = Sampler::new(SamplerDescriptor::minification(FilterMode::Ewa)).unwrap();
    assert_eq!(one.sample(&tex, &fp), sixteen.sample(&tex, &fp));
}

/// Under `Repeat` a texture is periodic, so moving a footprint's centre by whole periods leaves
/// trilinear and EWA samples unchanged, bit for bit, where the shift is exact in `f32` (centres on
/// multiples of 1/1024, periods of a power-of-two texture): the shifted samples wrap every tap
/// (trilinear's staged route for taps more than a texel outside, `Pass::far_repeat`; EWA's lines
/// wrapped by a mask), the unshifted ones read inside the texture. Tall, wide and rotated
/// ellipses (EWA scans columns for the tall ones, rows for the others), one sample at a time and
/// batched.
#[test]
fn whole_period_shifts_under_repeat_change_nothing() {
    let textures = [
        noise_texture(64, 64, Format::Rgba8Unorm, 5),
        noise_texture(128, 32, Format::Rgba8Srgb, 6),
    ];
    let shifts = [(1.0f32, 0.0f32), (0.0, 1.0), (-2.0, 3.0), (5.0, -4.0)];
    for tex in &textures {
        let (w, h) = (tex.width(), tex.height());
        let mut fps = Vec::new();
        for k in 0..60u32 {
            // Centres in [0.375, 0.625) on multiples of 1/1024; axes up to 8 x 1.5 texels.
            let (u, v) = (
                (384 + (k * 37) % 256) as f32 / 1024.0,
                (384 + (k * 91) % 256) as f32 / 1024.0,
            );
            let (px, py) = axes(1.5, 1.0 + (k % 5) as f32, k as f32 * 0.4);
            fps.push(footprint(u, v, px, py, w, h));
        }
        for name in ["trilinear", "ewa"] {
            let s = sampler(name, AddressMode::Repeat);
            let mut want = vec![[0.0f32; 4]; fps.len()];
            s.sample_batch(tex, &fps, &mut want);
            for (f, o) in fps.iter().zip(&want) {
                assert_eq!(s.sample(tex, f).map(f32::to_bits), o.map(f32::to_bits));
            }
            for (du, dv) in shifts {
                let moved: Vec<Footprint> = fps
                    .iter()
                    .map(|f| Footprint {
                        u: f.u + du,
                        v: f.v + dv,
                        ..*f
                    })
                    .collect();
                let mut got = vec![[0.0f32; 4]; fps.len()];
                s.sample_batch(tex, &moved, &mut got);
                for ((f, g), o) in moved.iter().zip(&got).zip(&want) {
                    let bits = o.map(f32::to_bits);
                    assert_eq!(g.map(f32::to_bits), bits, "{name} batch {f:?}");
                    assert_eq!(s.sample(tex, f).map(f32::to_bits), bits, "{name} {f:?}");
                }
            }
        }
    }
}
