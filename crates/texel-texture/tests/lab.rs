//! The lab's eight modes under both conventions: the rule evaluator under [`Rules::GL`] against
//! texel's samplers, the lab convention's sampler against the evaluator, and the handout's
//! formulas at points where they have closed forms.

use proptest::prelude::*;
use texel_texture::{
    Address, AddressMode, BorderColor, ColorSpace, Convention, Filter, Footprint, Limits, Rules,
    Sampler, SamplerDescriptor, Texture, TextureError,
};

/// A 64 x 64 linear texture of pseudo-random texels (every texel distinct from its neighbours).
fn noise(w: u32, h: u32) -> Texture {
    let mut s = 0x9e37_79b9_u32;
    let texels = (0..w * h)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            let b = s.to_le_bytes();
            [b[0], b[1], b[2], 255]
        })
        .collect();
    Texture::from_rgba8(w, h, texels, ColorSpace::Linear, &Limits::default()).unwrap()
}

fn repeat(mode: u8) -> Sampler {
    Sampler::new(
        Filter::from_lab_mode(mode)
            .unwrap()
            .descriptor(AddressMode::Repeat, AddressMode::Repeat),
    )
    .unwrap()
}

fn address() -> Address {
    Address::new(
        AddressMode::Repeat,
        AddressMode::Repeat,
        BorderColor::TransparentBlack,
    )
}

fn footprint() -> impl Strategy<Value = Footprint> {
    let d = prop_oneof![-0.3f32..0.3, -0.02f32..0.02, -0.002f32..0.002];
    (
        -3.0f32..3.0,
        -3.0f32..3.0,
        d.clone(),
        d.clone(),
        d.clone(),
        d,
    )
        .prop_map(|(u, v, dudx, dudy, dvdx, dvdy)| Footprint {
            u,
            v,
            dudx,
            dudy,
            dvdx,
            dvdy,
        })
}

fn close(a: [f32; 4], b: [f32; 4], tol: f32) -> bool {
    a.iter().zip(&b).all(|(x, y)| (x - y).abs() <= tol)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Under the GL rules the evaluator is texel's sampler (within float reassociation; a
    /// sample whose lod or index sits on a rounding edge may pick the other side, so a few
    /// outliers are allowed by checking most of a mode's samples in the next test instead).
    #[test]
    fn gl_rules_are_the_samplers(fp in footprint(), mode in 1u8..=8, w in prop_oneof![Just(64u32), Just(48)]) {
        let tex = noise(w, 64);
        let s = repeat(mode);
        let (want, _) = s.sample_counted(&tex, &fp);
        let (got, _) = tex.sample_rules(&address(), mode, &Rules::GL, &fp);
        prop_assume!(!on_edge(&tex, &fp, mode));
        prop_assert!(close(want, got, 2e-5), "mode {mode} {fp:?}: sampler {want:?} rules {got:?}");
    }

    /// The lab convention's sampler is the evaluator under the lab's rules, bit for bit, one
    /// sample at a time and in batches.
    #[test]
    fn lab_convention_is_the_lab_rules(fp in footprint(), mode in 1u8..=8) {
        let tex = noise(64, 64);
        let s = repeat(mode).with_convention(Convention::Lab).unwrap();
        prop_assert_eq!(s.convention(), Convention::Lab);
        let (want, _) = tex.sample_rules(&address(), mode, &Rules::LAB, &fp);
        prop_assert_eq!(s.sample(&tex, &fp), want);
        let mut out = [[0.0; 4]; 1];
        s.sample_batch(&tex, &[fp][..], &mut out);
        prop_assert_eq!(out[0], want);
    }
}

/// Whether `fp` sits within float noise of a rounding edge of `mode` under the GL rules (a texel
/// boundary for nearest, a level boundary for the mip modes), where two correct evaluations may
/// differ by a whole texel or level.
fn on_edge(tex: &Texture, fp: &Footprint, mode: u8) -> bool {
    let near = |x: f32| (x - x.round()).abs() < 1e-3;
    let (w, h) = (tex.width() as f32, tex.height() as f32);
    let rho = (fp.dudx * w)
        .hypot(fp.dvdx * h)
        .max((fp.dudy * w).hypot(fp.dvdy * h));
    let lod = rho.log2();
    let texel_edge = near(fp.u * w) || near(fp.v * h);
    let half_edge = near(fp.u * w - 0.5) || near(fp.v * h - 0.5);
    match mode {
        1 => texel_edge,
        3 => near(lod - 0.5) || near(lod) || half_edge,
        _ => near(lod) || half_edge,
    }
}

/// Over a sweep of footprints, the evaluator under GL agrees with the sampler on all but a
/// handful of samples on rounding edges, in every mode.
#[test]
fn gl_rules_match_the_sampler_on_a_sweep() {
    let tex = noise(64, 64);
    for mode in 1..=8u8 {
        let s = repeat(mode);
        let (mut n, mut off) = (0, 0);
        for k in 0..4000 {
            let t = k as f32 / 4000.0;
            let a = t * 37.0;
            let fp = Footprint {
                u: -1.3 + 2.7 * t,
                v: 0.4 + 0.9 * (a).sin(),
                dudx: 0.02 * a.cos(),
                dudy: 0.001 + 0.004 * t,
                dvdx: 0.003 * (2.0 * a).sin(),
                dvdy: 0.05 * t * t,
            };
            let (want, _) = s.sample_counted(&tex, &fp);
            let (got, _) = tex.sample_rules(&address(), mode, &Rules::GL, &fp);
            n += 1;
            if !close(want, got, 2e-5) {
                off += 1;
            }
        }
        assert!(off * 1000 <= n, "mode {mode}: {off} of {n} samples differ");
    }
}

/// The handout's nearest rounds: texel `round(W u)`, so `u = 2.6 / W` reads texel 3 where GL's
/// floor reads texel 2.
#[test]
fn lab_nearest_rounds() {
    let tex = noise(8, 8);
    let at = |x: f32, rules: &Rules| {
        let fp = Footprint::point(x / 8.0, 0.2 / 8.0);
        tex.sample_rules(&address(), 1, rules, &fp).0
    };
    assert_eq!(at(2.6, &Rules::LAB), tex.texel(0, 3, 0).unwrap());
    assert_eq!(at(2.6, &Rules::GL), tex.texel(0, 2, 0).unwrap());
    // 7.6 rounds to 8, which repeats to texel 0.
    assert_eq!(at(7.6, &Rules::LAB), tex.texel(0, 0, 0).unwrap());
}

/// The handout's bilinear has its texels at integer coordinates: at `x = 3` it is texel 3 alone,
/// and at `x = 3.25` a quarter of the way to texel 4.
#[test]
fn lab_bilinear_has_texels_at_integers() {
    let tex = noise(8, 8);
    let at = |x: f32| {
        let fp = Footprint::point(x / 8.0, 5.0 / 8.0);
        tex.sample_rules(&address(), 2, &Rules::LAB, &fp).0
    };
    let t3 = tex.texel(0, 3, 5).unwrap();
    let t4 = tex.texel(0, 4, 5).unwrap();
    assert!(close(at(3.0), t3, 1e-6));
    let want: Vec<f32> = t3
        .iter()
        .zip(&t4)
        .map(|(a, b)| a + (b - a) * 0.25)
        .collect();
    assert!(close(at(3.25), want.try_into().unwrap(), 1e-6));
}

/// Mode 3 under the lab reads the coarser level `ceil(N)`: with `N = 1.2` it reads level 2,
/// where GL reads the nearest level, 1. Mode 4 blends levels 1 and 2 by 0.2 in both.
#[test]
fn lab_mip_level_is_the_coarser() {
    let tex = noise(64, 64);
    let len = 2f32.powf(1.2) / 64.0;
    let fp = Footprint {
        u: 0.3,
        v: 0.6,
        dudx: len,
        dudy: 0.0,
        dvdx: 0.0,
        dvdy: len,
    };
    let lab3 = tex.sample_rules(&address(), 3, &Rules::LAB, &fp).0;
    let gl3 = tex.sample_rules(&address(), 3, &Rules::GL, &fp).0;
    let lab_level = |k: f32| {
        // A footprint whose N is exactly k reads level k alone in mode 4.
        let l = 2f32.powf(k) / 64.0;
        let f = Footprint {
            dudx: l,
            dvdy: l,
            ..fp
        };
        tex.sample_rules(&address(), 4, &Rules::LAB, &f).0
    };
    assert!(close(lab3, lab_level(2.0), 1e-6));
    let gl_level = |k: f32| {
        let l = 2f32.powf(k) / 64.0;
        let f = Footprint {
            dudx: l,
            dvdy: l,
            ..fp
        };
        tex.sample_rules(&address(), 4, &Rules::GL, &f).0
    };
    assert!(close(gl3, gl_level(1.0), 1e-6));
    let lab4 = tex.sample_rules(&address(), 4, &Rules::LAB, &fp).0;
    let (a, b) = (lab_level(1.0), lab_level(2.0));
    let want: Vec<f32> = a.iter().zip(&b).map(|(a, b)| a + (b - a) * 0.2).collect();
    assert!(close(lab4, want.try_into().unwrap(), 1e-5));
}

/// The lab's probes include the footprint's ends: with anisotropy exactly 2 (mode 5), two probes
/// at `P -+ Pmax / 2`; GL's two probes sit at `P -+ Pmax / 4`.
#[test]
fn lab_probes_span_the_footprint() {
    let tex = noise(64, 64);
    let (minor, major) = (1.0 / 64.0, 2.0 / 64.0);
    let fp = Footprint {
        u: 0.41,
        v: 0.27,
        dudx: major,
        dudy: 0.0,
        dvdx: 0.0,
        dvdy: minor,
    };
    let tri = |u: f32, rules: &Rules| {
        let f = Footprint {
            u,
            dudx: minor,
            ..fp
        };
        tex.sample_rules(&address(), 4, rules, &f).0
    };
    let avg = |a: [f32; 4], b: [f32; 4]| -> [f32; 4] {
        let v: Vec<f32> = a.iter().zip(&b).map(|(a, b)| (a + b) / 2.0).collect();
        v.try_into().unwrap()
    };
    let lab = tex.sample_rules(&address(), 5, &Rules::LAB, &fp).0;
    assert!(close(
        lab,
        avg(
            tri(fp.u - major / 2.0, &Rules::LAB),
            tri(fp.u + major / 2.0, &Rules::LAB)
        ),
        1e-5
    ));
    let gl = tex.sample_rules(&address(), 5, &Rules::GL, &fp).0;
    assert!(close(
        gl,
        avg(
            tri(fp.u - major / 4.0, &Rules::GL),
            tri(fp.u + major / 4.0, &Rules::GL)
        ),
        1e-5
    ));
}

/// The lab convention exists for the eight modes only.
#[test]
fn lab_convention_needs_a_lab_mode() {
    let ewa = Sampler::new(SamplerDescriptor::minification(
        texel_texture::FilterMode::Ewa,
    ))
    .unwrap();
    assert!(matches!(
        ewa.with_convention(Convention::Lab),
        Err(TextureError::LabConventionNeedsLabMode)
    ));
    let back = repeat(4)
        .with_convention(Convention::Lab)
        .unwrap()
        .with_convention(Convention::Gl)
        .unwrap();
    assert_eq!(back.convention(), Convention::Gl);
    assert_eq!("lab".parse::<Convention>(), Ok(Convention::Lab));
    assert!("opengl".parse::<Convention>().is_err());
}
