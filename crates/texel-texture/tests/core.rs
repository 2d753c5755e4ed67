//! Properties of the core filters (nearest, bilinear, bicubic, mip-nearest, trilinear), the pyramid,
//! texture loading and hostile inputs.

use proptest::prelude::*;
use texel_texture::{
    Address, AddressMode, BorderColor, ColorSpace, Cubic, Filter, FilterMode, Footprint,
    FootprintBatch, FootprintLanes, Format, Lanes, Limits, MipmapFilterMode, Sampler,
    SamplerDescriptor, SpanKind, Texture, TextureError, Wants,
};

/// The bytes `s` bound to `tex` gives for `wants`, into `out`, when its spans are `kind`;
/// `false`, writing nothing, when they are another kind.
fn span_bytes(
    s: &Sampler,
    tex: &Texture,
    wants: Wants,
    kind: SpanKind,
    fps: impl FootprintBatch,
    out: &mut [[u8; 4]],
) -> bool {
    let bound = s.bind(tex, wants);
    bound.kind() == kind && bound.sample_span(Lanes::scalar(), fps, &mut [], out) == kind
}

/// The texel's stored bytes (`SpanKind::Stored`), where the sampler reads one texel.
fn stored_bytes(s: &Sampler, tex: &Texture, fps: impl FootprintBatch, out: &mut [[u8; 4]]) -> bool {
    let wants = Wants {
        stored_bytes: true,
        fixed8: false,
    };
    span_bytes(s, tex, wants, SpanKind::Stored, fps, out)
}

/// The fixed-point codes (`SpanKind::Fixed8`), where they apply.
fn fixed8_codes(s: &Sampler, tex: &Texture, fps: impl FootprintBatch, out: &mut [[u8; 4]]) -> bool {
    let wants = Wants {
        stored_bytes: false,
        fixed8: true,
    };
    span_bytes(s, tex, wants, SpanKind::Fixed8, fps, out)
}

const ADDRESS_MODES: [AddressMode; 5] = [
    AddressMode::ClampToEdge,
    AddressMode::Repeat,
    AddressMode::MirrorRepeat,
    AddressMode::ClampToBorder,
    AddressMode::MirrorClampToEdge,
];

const FILTERS: [FilterMode; 5] = [
    FilterMode::Nearest,
    FilterMode::Linear,
    FilterMode::Cubic(Cubic::CATMULL_ROM),
    FilterMode::Cubic(Cubic::MITCHELL),
    FilterMode::Cubic(Cubic::B_SPLINE),
];

const MIPMAPS: [MipmapFilterMode; 3] = [
    MipmapFilterMode::None,
    MipmapFilterMode::Nearest,
    MipmapFilterMode::Linear,
];

fn sampler(mag: FilterMode, min: FilterMode, mip: MipmapFilterMode, addr: AddressMode) -> Sampler {
    Sampler::new(SamplerDescriptor {
        mag_filter: mag,
        min_filter: min,
        mipmap_filter: mip,
        ..SamplerDescriptor::default().with_address_mode(addr)
    })
    .unwrap()
}

fn every_sampler(border: BorderColor) -> Vec<Sampler> {
    let mut v = Vec::new();
    for addr in ADDRESS_MODES {
        for f in FILTERS {
            for mip in MIPMAPS {
                let mut d = SamplerDescriptor {
                    mag_filter: f,
                    min_filter: f,
                    mipmap_filter: mip,
                    ..SamplerDescriptor::default().with_address_mode(addr)
                };
                d.border_color = border;
                v.push(Sampler::new(d).unwrap());
            }
        }
    }
    v
}

/// Deterministic noise in [0, 1) (SplitMix64), so tests need no RNG crate.
fn noise(seed: u64) -> f32 {
    let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 40) as f32 / (1u64 << 24) as f32
}

fn noise_texture(w: u32, h: u32, format: Format) -> Texture {
    Texture::from_fn(w, h, format, &Limits::default(), |i, j| {
        let k = u64::from(j) * u64::from(w) + u64::from(i);
        [noise(4 * k), noise(4 * k + 1), noise(4 * k + 2), 1.0]
    })
    .unwrap()
}

/// The `k`-th position of a low-discrepancy sequence in `[0, 1)^2` (steps of 0.618 along u, 0.37
/// of that along v): neighbouring samples land apart, so each chunk spreads over the texture.
fn spread(k: usize) -> (f32, f32) {
    let t = k as f32 * 0.618;
    (t.fract(), (t * 0.37).fract())
}

/// `per` footprints for each `(major, minor)` pair of axis lengths (texels of a 64-texel side):
/// footprint `j` of a pair turned by `j * turn` radians, centred at `centre` of the `k`-th
/// [`spread`] position (per coordinate).
fn rotated_footprints(
    axes: &[(f32, f32)],
    per: usize,
    turn: f32,
    centre: impl Fn(f32) -> f32 + Copy,
) -> Vec<Footprint> {
    axes.iter()
        .enumerate()
        .flat_map(|(k, &(major, minor))| {
            (0..per).map(move |j| {
                let (u, v) = spread(k * per + j);
                let a = j as f32 * turn;
                let (c, s) = (a.cos() / 64.0, a.sin() / 64.0);
                Footprint {
                    u: centre(u),
                    v: centre(v),
                    dudx: major * c,
                    dvdx: major * s,
                    dudy: -minor * s,
                    dvdy: minor * c,
                }
            })
        })
        .collect()
}

/// `fps` as lanes: `u`, `v` and `[dudx, dudy, dvdx, dvdy]` (for [`FootprintLanes::new`]).
fn lanes_of(fps: &[Footprint]) -> (Vec<f32>, Vec<f32>, [Vec<f32>; 4]) {
    let field = |f: fn(&Footprint) -> f32| fps.iter().map(f).collect::<Vec<_>>();
    let d = [
        field(|f| f.dudx),
        field(|f| f.dudy),
        field(|f| f.dvdx),
        field(|f| f.dvdy),
    ];
    (field(|f| f.u), field(|f| f.v), d)
}

/// The bits of a batch's output, for comparisons.
fn bits(v: &[[f32; 4]]) -> Vec<u32> {
    v.iter().flatten().map(|x| x.to_bits()).collect()
}

/// `sample_batch` of `fps` given as [`FootprintLanes`] equals it given as structs, bit for bit.
fn assert_lanes_equal_structs(s: &Sampler, tex: &Texture, fps: &[Footprint], case: &str) {
    let (u, v, d) = lanes_of(fps);
    let lanes = FootprintLanes::new(&u, &v, [&d[0], &d[1], &d[2], &d[3]]);
    let mut structs = vec![[0.0; 4]; fps.len()];
    let mut from_lanes = vec![[1.0; 4]; fps.len()];
    s.sample_batch(tex, fps, &mut structs);
    s.sample_batch(tex, lanes, &mut from_lanes);
    assert_eq!(bits(&structs), bits(&from_lanes), "lanes: {case}");
}

/// `sample_batch` (on the CPU's best copy: the eight-lane quad kernel and its runs where the CPU
/// has AVX2) and `sample_batch_lanes` with [`Lanes::scalar`] (the four-lane kernel, and the
/// per-sample loops where the run kernel declines) of `fps` each equal `sample` bit for bit;
/// `case` names the sampler in a failure.
fn assert_batches_equal_single(s: &Sampler, tex: &Texture, fps: &[Footprint], case: &str) {
    let mut out = vec![[0.0; 4]; fps.len()];
    let mut wide = out.clone();
    s.sample_batch(tex, fps, &mut out);
    s.sample_batch_lanes(Lanes::scalar(), tex, fps, &mut wide);
    for ((fp, o), w) in fps.iter().zip(&out).zip(&wide) {
        let single = s.sample(tex, fp).map(f32::to_bits);
        assert_eq!(single, o.map(f32::to_bits), "{case} {fp:?}");
        assert_eq!(single, w.map(f32::to_bits), "lanes: {case} {fp:?}");
    }
    assert_lanes_equal_structs(s, tex, fps, case);
}

fn footprint_strategy() -> impl Strategy<Value = Footprint> {
    let d = prop_oneof![Just(0.0f32), -0.5f32..0.5, -1e-3f32..1e-3, -20.0f32..20.0];
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

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A constant texture is constant under every filter, address mode and footprint
    /// (the border colour is set to the same constant so ClampToBorder agrees too).
    #[test]
    fn constant_texture_is_constant(fp in footprint_strategy(), w in 1u32..40, h in 1u32..40) {
        let c = [0.25f32, 0.5, 0.75, 1.0];
        let float = Texture::from_fn(w, h, Format::Rgba32Float, &Limits::default(), |_, _| c).unwrap();
        // 8-bit linear: 64/255 etc. are exact codes, so compare against the decoded constant.
        let bytes = Texture::from_rgba8(w, h, vec![[64, 128, 191, 255]; (w * h) as usize], ColorSpace::Srgb, &Limits::default()).unwrap();
        let c8 = bytes.texel(0, 0, 0).unwrap();
        for s in every_sampler(BorderColor::Custom(c)) {
            let got = s.sample(&float, &fp);
            for k in 0..4 {
                prop_assert!((got[k] - c[k]).abs() < 1e-5, "{:?} {:?} -> {:?}", s.descriptor(), fp, got);
            }
        }
        for s in every_sampler(BorderColor::Custom(c8)) {
            let got = s.sample(&bytes, &fp);
            for k in 0..4 {
                // Mip levels of an 8-bit texture are re-quantised; a constant survives exactly.
                prop_assert!((got[k] - c8[k]).abs() < 1e-5, "{:?} {:?} -> {:?}", s.descriptor(), fp, got);
            }
        }
    }

    /// Nearest returns texel floor(xy) of level 0 (after wrapping) when magnifying.
    #[test]
    fn nearest_is_floor(u in -2.0f32..3.0, v in -2.0f32..3.0, addr in 0usize..5) {
        let tex = noise_texture(13, 7, Format::Rgba32Float);
        let mode = ADDRESS_MODES[addr];
        let s = sampler(FilterMode::Nearest, FilterMode::Nearest, MipmapFilterMode::None, mode);
        let got = s.sample(&tex, &Footprint::point(u, v));
        let i = mode.wrap((u * 13.0).floor() as i64, 13);
        let j = mode.wrap((v * 7.0).floor() as i64, 7);
        let want = match (i, j) {
            (Some(i), Some(j)) => tex.texel(0, i, j).unwrap(),
            _ => [0.0; 4],
        };
        prop_assert_eq!(got, want);
    }

    /// Without mipmapping and with `mag_filter == min_filter` the sampler skips the lod: its result
    /// equals the min filter at level 0 forced by a lod clamp of `[0.25, 0.25]` (nearest level 0),
    /// for every footprint, filter and address mode.
    #[test]
    fn lod_free_samplers_equal_forced_min_filter(fp in footprint_strategy(), addr in 0usize..5, f in 0usize..3) {
        let tex = noise_texture(13, 7, Format::Rgba8Srgb);
        let filter = [FilterMode::Nearest, FilterMode::Linear, FilterMode::Cubic(Cubic::MITCHELL)][f];
        let mode = ADDRESS_MODES[addr];
        let free = sampler(filter, filter, MipmapFilterMode::None, mode);
        let forced = Sampler::new(SamplerDescriptor {
            lod_min_clamp: 0.25,
            lod_max_clamp: 0.25,
            ..*sampler(filter, filter, MipmapFilterMode::Nearest, mode).descriptor()
        })
        .unwrap();
        prop_assert_eq!(free.sample(&tex, &fp), forced.sample(&tex, &fp));
    }

    /// Bilinear reproduces a linear ramp exactly between texel centres.
    #[test]
    fn bilinear_reproduces_ramp(x in 0.5f32..31.5, y in 0.5f32..15.5) {
        let tex = Texture::from_fn(32, 16, Format::Rgba32Float, &Limits::default(), |i, j| {
            [i as f32, j as f32, 2.0 * i as f32 + 3.0 * j as f32, 1.0]
        }).unwrap();
        let s = sampler(FilterMode::Linear, FilterMode::Linear, MipmapFilterMode::None, AddressMode::ClampToEdge);
        let got = s.sample(&tex, &Footprint::point(x / 32.0, y / 16.0));
        let (ex, ey) = (x - 0.5, y - 0.5);
        prop_assert!((got[0] - ex).abs() < 1e-4, "{got:?} vs {ex}");
        prop_assert!((got[1] - ey).abs() < 1e-4);
        prop_assert!((got[2] - (2.0 * ex + 3.0 * ey)).abs() < 1e-3);
    }

    /// The cubic B-spline is a convex combination: never outside the texels' range.
    #[test]
    fn bspline_does_not_overshoot(u in -1.0f32..2.0, v in -1.0f32..2.0) {
        let tex = noise_texture(9, 11, Format::Rgba32Float);
        let s = sampler(FilterMode::Cubic(Cubic::B_SPLINE), FilterMode::Cubic(Cubic::B_SPLINE), MipmapFilterMode::None, AddressMode::Repeat);
        let got = s.sample(&tex, &Footprint::point(u, v));
        for (k, &g) in got.iter().enumerate().take(3) {
            let (mut lo, mut hi) = (f32::MAX, f32::MIN);
            for j in 0..11 { for i in 0..9 { let t = tex.texel(0, i, j).unwrap()[k]; lo = lo.min(t); hi = hi.max(t); } }
            prop_assert!(g >= lo - 1e-6 && g <= hi + 1e-6);
        }
    }

    /// `sample_batch` equals `sample` one by one, bit for bit (lengths beyond the 64-footprint
    /// chunk included): the staged kernels of the core filters (`batch.rs`) and the generic path,
    /// for every filter, mipmap mode and address mode, on 8-bit sRGB, 8-bit linear and float
    /// textures of odd sizes (a 1-texel-wide one included); and with [`Lanes::scalar`]'s quad
    /// kernel (`sample_batch_lanes`), equal to `sample_batch` (which takes the eight-lane
    /// kernel where the CPU has AVX2).
    #[test]
    fn batch_equals_single(
        fps in proptest::collection::vec(footprint_strategy(), 1..150),
        (w, h) in prop_oneof![Just((64u32, 32u32)), Just((37, 5)), Just((1, 9)), Just((3, 3))],
    ) {
        let textures = [
            noise_texture(w, h, Format::Rgba8Srgb),
            noise_texture(w, h, Format::Rgba8Unorm),
            noise_texture(w, h, Format::Rgba32Float),
        ];
        let mut samplers = every_sampler(BorderColor::OpaqueWhite);
        samplers.push(sampler(FilterMode::Linear, FilterMode::Cubic(Cubic::MITCHELL), MipmapFilterMode::Linear, AddressMode::MirrorRepeat));
        samplers.push(sampler(FilterMode::Nearest, FilterMode::Linear, MipmapFilterMode::Linear, AddressMode::Repeat));
        for d in [
            SamplerDescriptor::anisotropic(16),
            SamplerDescriptor::minification(FilterMode::Ewa),
            SamplerDescriptor::minification(FilterMode::Ripmap),
            SamplerDescriptor::minification(FilterMode::SummedArea),
        ] {
            samplers.push(Sampler::new(d.with_address_mode(AddressMode::MirrorRepeat)).unwrap());
        }
        let mut out = vec![[0.0; 4]; fps.len()];
        let mut wide = vec![[0.0; 4]; fps.len()];
        for tex in &textures {
            for s in &samplers {
                s.sample_batch(tex, &fps, &mut out);
                for (f, o) in fps.iter().zip(&out) {
                    prop_assert_eq!(s.sample(tex, f).map(f32::to_bits), o.map(f32::to_bits), "{:?} {:?}", s.descriptor(), f);
                }
                // The four-lane quad kernel gives the same bits as `sample_batch`'s (the
                // eight-lane one where the CPU has AVX2).
                s.sample_batch_lanes(Lanes::scalar(), tex, &fps, &mut wide);
                prop_assert_eq!(bits(&out), bits(&wide), "{:?}", s.descriptor());
                // The same footprints as lanes (`FootprintLanes`): the same bits.
                let (u, v, d) = lanes_of(&fps);
                let lanes = FootprintLanes::new(&u, &v, [&d[0], &d[1], &d[2], &d[3]]);
                s.sample_batch(tex, lanes, &mut wide);
                prop_assert_eq!(bits(&out), bits(&wide), "lanes {:?}", s.descriptor());
            }
        }
    }
}

/// The anisotropic batch routes every sample through its probe batches (docs/decisions.md): a
/// magnified sample as one bilinear probe in level 0, an isotropic one as one trilinear probe,
/// an anisotropic one as its `N` probes, and a batch whose probes all lie inside both levels
/// through the run kernels. Rows like the ground's (magnified near the viewer, ever more
/// anisotropic towards the horizon, each row's samples in the same levels) on a linear 8-bit
/// texture (the run kernels), an sRGB one and a float one, under Repeat, ClampToEdge and
/// ClampToBorder, and with probes far outside the texture; `sample_batch` equals `sample` bit
/// for bit.
#[test]
fn anisotropic_batch_equals_single_across_its_kinds_of_sample() {
    let textures = [
        noise_texture(256, 128, Format::Rgba8Unorm),
        noise_texture(96, 80, Format::Rgba8Srgb),
        noise_texture(64, 64, Format::Rgba32Float),
    ];
    let mut fps = Vec::new();
    for row in 0..40 {
        // Derivatives per pixel, in uv: from a tenth of a texel (magnified) to 64 texels along u
        // with up to a 20:1 ratio.
        let scale = 0.0004 * 1.25f32.powi(row);
        let ratio = 1.0 + (row % 20) as f32;
        for k in 0..70 {
            let (u, v) = spread(row as usize * 70 + k);
            let (u, v) = (u * 0.5 + 0.25, v * 0.5 + 0.25);
            fps.push(Footprint {
                u,
                v,
                dudx: scale * ratio,
                dudy: 0.0,
                dvdx: 0.0,
                dvdy: scale,
            });
        }
    }
    // Probes far outside the texture too.
    fps.extend((0..50).map(|k| Footprint {
        u: 3.5 - k as f32 * 0.15,
        v: -2.25,
        dudx: 0.05,
        dudy: 0.001,
        dvdx: -0.002,
        dvdy: 0.003,
    }));
    let mut out = vec![[f32::NAN; 4]; fps.len()];
    for addr in [
        AddressMode::Repeat,
        AddressMode::ClampToEdge,
        AddressMode::ClampToBorder,
    ] {
        let d = SamplerDescriptor::anisotropic(16).with_address_mode(addr);
        let s = Sampler::new(d).unwrap();
        for (t, tex) in textures.iter().enumerate() {
            s.sample_batch(tex, &fps, &mut out);
            for (f, o) in fps.iter().zip(&out) {
                let want = s.sample(tex, f).map(f32::to_bits);
                assert_eq!(o.map(f32::to_bits), want, "texture {t} {addr:?} {f:?}");
            }
        }
    }
}

/// Neighbouring anisotropic samples whose probes read different pairs of levels (lods just
/// below and above an integer, a third pair, magnified and isotropic samples), in every order the
/// cycle gives: the batch keeps a probe batch per pair of levels and flushes the older one when
/// a third pair comes (docs/decisions.md); `sample_batch` equals `sample` bit for bit.
#[test]
fn anisotropic_batch_equals_single_when_neighbours_alternate_levels() {
    let tex = noise_texture(128, 128, Format::Rgba8Unorm);
    // Minor axes in texels: probe lods about 1 - 1e-6, 1 + 1e-6, 2.5; a magnified sample; an
    // isotropic one.
    let minors = [2.0 * (1.0 - 1e-6f32), 2.0 * (1.0 + 1e-6), 5.66, 0.25, 3.0];
    let ratios = [4.0f32, 4.0, 8.0, 4.0, 1.0];
    let fps: Vec<Footprint> = (0..300)
        .map(|k| {
            let c = (k * 7 + k / 5) % minors.len();
            let (u, v) = spread(k);
            let d = minors[c] / 128.0;
            Footprint {
                u: u * 0.6 + 0.2,
                v: v * 0.6 + 0.2,
                dudx: d * ratios[c],
                dudy: 0.0,
                dvdx: 0.0,
                dvdy: d,
            }
        })
        .collect();
    let s = Sampler::new(SamplerDescriptor::anisotropic(16)).unwrap();
    let mut out = vec![[f32::NAN; 4]; fps.len()];
    s.sample_batch(&tex, &fps, &mut out);
    for (f, o) in fps.iter().zip(&out) {
        assert_eq!(
            o.map(f32::to_bits),
            s.sample(&tex, f).map(f32::to_bits),
            "{f:?}"
        );
    }
}

/// `sample_batch` equals `sample` bit for bit on the lod's edge cases: zero, subnormal, huge,
/// infinite and NaN derivatives (the batch lod stage's scalar fix-up and its non-finite select),
/// with lod biases large enough that a subnormal `rho^2` does not clamp to `lod_min`.
#[test]
fn batch_equals_single_on_extreme_derivatives() {
    let tex = noise_texture(64, 32, Format::Rgba8Srgb);
    let ds = [
        0.0f32,
        -0.0,
        1e-45,
        1e-40,
        1e-30,
        1e-20,
        3e-19,
        1e-3,
        0.7,
        1e19,
        3e38,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
    ];
    let mut fps = Vec::new();
    for (k, &a) in ds.iter().enumerate() {
        for &b in &ds {
            let t = k as f32 * 0.37;
            fps.push(Footprint {
                u: t,
                v: 1.0 - t,
                dudx: a,
                dudy: b,
                dvdx: b * 0.5,
                dvdy: a,
            });
        }
    }
    for bias in [0.0f32, 5.0, 70.0, -70.0, 200.0] {
        for mip in [MipmapFilterMode::Nearest, MipmapFilterMode::Linear] {
            for f in [FilterMode::Nearest, FilterMode::Linear] {
                let s = Sampler::new(SamplerDescriptor {
                    lod_bias: bias,
                    ..*sampler(f, f, mip, AddressMode::Repeat).descriptor()
                })
                .unwrap();
                let mut out = vec![[0.0; 4]; fps.len()];
                s.sample_batch(&tex, &fps, &mut out);
                for (fp, o) in fps.iter().zip(&out) {
                    assert_eq!(
                        s.sample(&tex, fp).map(f32::to_bits),
                        o.map(f32::to_bits),
                        "bias {bias} {mip:?} {f:?} {fp:?}"
                    );
                }
            }
        }
    }
}

/// `sample_batch` equals `sample` bit for bit where whole chunks share one level (the batch's
/// one-level path: the view and size looked up once per chunk) and where one sample of a chunk
/// leaves it: footprints of one fractional lod (1.3; 0.6 for the nearest-mip rounding; 2.9, near
/// the last level of a 64-texel side; 7.5, beyond every texture's last level, where a trilinear
/// chunk blends nothing and takes the unblended path; -1, magnified, level 0 with a zero blend
/// weight) at spread positions, 64-sample chunks with and without an outlier, every mipmap mode
/// and filter, the three formats.
#[test]
fn batch_equals_single_when_a_chunk_shares_a_level() {
    let textures = [
        noise_texture(64, 64, Format::Rgba8Srgb),
        noise_texture(64, 64, Format::Rgba8Unorm),
        noise_texture(61, 37, Format::Rgba32Float),
    ];
    for lod in [1.3f32, 0.6, 2.9, 7.5, -1.0] {
        // rho = 2^lod texels of the 64-texel side, along u.
        let d = lod.exp2() / 64.0;
        let mut fps: Vec<Footprint> = (0..200)
            .map(|k| {
                let (x, y) = spread(k);
                Footprint {
                    u: x * 1.5 - 0.2,
                    v: y,
                    dudx: d,
                    dvdx: 0.0,
                    dudy: 0.0,
                    dvdy: d * 0.5,
                }
            })
            .collect();
        // The third chunk has one sample two levels coarser.
        fps[150].dudx = d * 4.0;
        for tex in &textures {
            for mip in [MipmapFilterMode::Nearest, MipmapFilterMode::Linear] {
                for f in [FilterMode::Nearest, FilterMode::Linear] {
                    for addr in ADDRESS_MODES {
                        let s = sampler(f, f, mip, addr);
                        let mut out = vec![[0.0; 4]; fps.len()];
                        s.sample_batch(tex, &fps, &mut out);
                        for (fp, o) in fps.iter().zip(&out) {
                            assert_eq!(
                                s.sample(tex, fp).map(f32::to_bits),
                                o.map(f32::to_bits),
                                "lod {lod} {mip:?} {f:?} {addr:?} {fp:?}"
                            );
                        }
                    }
                }
            }
        }
    }
}

/// `sample_batch` and `sample_batch_lanes` (the eight-lane kernel where the CPU has it) equal
/// `sample` bit for bit on chunks whose samples all lie inside one level (the batch's loop of
/// the inside route alone, docs/decisions.md; the other tests' positions reach the
/// level's edges, so few of their chunks are wholly inside) for each kind of trilinear chunk:
/// every blend weight positive (lod 1.5), none (lod 1.0 exactly, and -1: magnified), and some
/// (lods 1.0 and 1.5 alternating: one level, weights 0 and 0.5), plus one chunk with a sample near
/// the edge; and without mipmaps and with the nearest level (the routes entry 40's kept patch
/// changes). The lods are checked first, so that the footprints reach the cases they name.
#[test]
fn batch_equals_single_on_inside_runs() {
    let textures = [
        noise_texture(64, 64, Format::Rgba8Srgb),
        noise_texture(64, 64, Format::Rgba8Unorm),
        noise_texture(64, 64, Format::Rgba32Float),
    ];
    let lods: [&[f32]; 4] = [&[1.5], &[1.0], &[-1.0], &[1.0, 1.5]];
    for lods in lods {
        let fps: Vec<Footprint> = (0..200)
            .map(|k| {
                let (x, y) = spread(k);
                // rho = 2^lod texels of the 64-texel side, along u.
                let d = lods[k % lods.len()].exp2() / 64.0;
                Footprint {
                    u: 0.1 + 0.8 * x,
                    v: 0.1 + 0.8 * y,
                    dudx: d,
                    dvdx: 0.0,
                    dudy: 0.0,
                    dvdy: d * 0.5,
                }
            })
            .collect();
        let mut near_edge = fps.clone();
        near_edge[100].u = 0.001;
        let trilinear = sampler(
            FilterMode::Linear,
            FilterMode::Linear,
            MipmapFilterMode::Linear,
            AddressMode::Repeat,
        );
        for tex in &textures {
            for fp in &fps[..lods.len()] {
                let want = (fp.dudx * 64.0).log2();
                // Whole lods are exact (`fast_log2` of a power of two); 1.5 lies strictly
                // between levels 1 and 2 (within `fast_log2`'s 1.2 ulp of `log2`).
                let lod = trilinear.lod(tex, fp);
                if want.fract() == 0.0 {
                    assert_eq!(
                        lod,
                        want.max(0.0),
                        "the footprint's lod (clamped at lod_min 0)"
                    );
                } else {
                    assert!(lod > want.floor() && lod < want.ceil(), "lod {lod}");
                }
            }
            let mips = [
                MipmapFilterMode::None,
                MipmapFilterMode::Nearest,
                MipmapFilterMode::Linear,
            ];
            for mip in mips {
                for f in [FilterMode::Nearest, FilterMode::Linear] {
                    for addr in [AddressMode::Repeat, AddressMode::ClampToBorder] {
                        let s = sampler(f, f, mip, addr);
                        let case = format!("lods {lods:?} {mip:?} {f:?} {addr:?}");
                        for fps in [&fps, &near_edge] {
                            assert_batches_equal_single(&s, tex, fps, &case);
                        }
                    }
                }
            }
        }
    }
}

/// The batched anisotropic path (probes of several samples filtered together, flushed when 256
/// would overflow) equals `sample` bit for bit: chunks of strongly anisotropic footprints (16
/// probes each, so a 64-sample chunk flushes four times, and a sample's probes land at any offset
/// of the scratch), interleaved with isotropic, magnified and non-finite ones, then runs of one
/// shape whose batches share their levels; every clamp, the three texel formats, lengths that
/// leave a partial last chunk.
#[test]
fn batched_anisotropic_probes_equal_single_samples() {
    let mut fps = Vec::new();
    for k in 0..300 {
        let t = k as f32 * 0.173;
        let (u, v) = (t.sin() * 3.0, t.cos() * 2.0 + t * 0.1);
        // Major axis 2^(k % 9) texels of a 64-texel side over minor 1/8..1 texel, turning.
        let major = (1u32 << (k % 9)) as f32 / 64.0;
        let minor = (1.0 + (k % 8) as f32) / 8.0 / 64.0;
        let (c, s) = (t.cos(), t.sin());
        let fp = match k % 7 {
            // Isotropic, and magnified: one probe or the magnification filter.
            5 => Footprint {
                u,
                v,
                dudx: minor,
                dvdx: 0.0,
                dudy: 0.0,
                dvdy: minor,
            },
            6 if k % 2 == 0 => Footprint {
                u,
                v,
                dudx: 1e-4,
                dvdx: 0.0,
                dudy: 0.0,
                dvdy: 1e-4,
            },
            6 => Footprint {
                u: f32::NAN,
                v,
                dudx: f32::INFINITY,
                dvdx: 0.0,
                dudy: 0.0,
                dvdy: minor,
            },
            _ => Footprint {
                u,
                v,
                dudx: major * c,
                dvdx: major * s,
                dudy: -minor * s,
                dvdy: minor * c,
            },
        };
        fps.push(fp);
    }
    // Then 200 of one shape (8 texels by 1.5, a fractional probe lod) at spread positions, so
    // that whole probe batches share their two levels (the batch's one-level path).
    for k in 0..200 {
        let (x, v) = spread(k);
        let u = x * 1.5 - 0.2;
        fps.push(Footprint {
            u,
            v,
            dudx: 8.0 / 64.0,
            dvdx: 0.0,
            dudy: 0.0,
            dvdy: 1.5 / 64.0,
        });
    }
    // Then 300 of one shape whose probes all lie inside both levels (sample centres 13 to 51
    // texels of 64 along u, probes within about 9.5 to 54.5), so that whole batches share one
    // level pair with every probe inside (the route entry 40's kept patch filters level by level).
    for k in 0..300 {
        let (x, y) = spread(k);
        fps.push(Footprint {
            u: 0.2 + 0.6 * x,
            v: 0.2 + 0.6 * y,
            dudx: 8.0 / 64.0,
            dvdx: 0.0,
            dudy: 0.0,
            dvdy: 1.5 / 64.0,
        });
    }
    let textures = [
        noise_texture(64, 64, Format::Rgba8Srgb),
        noise_texture(64, 64, Format::Rgba8Unorm),
        noise_texture(61, 37, Format::Rgba32Float),
    ];
    for tex in &textures {
        for clamp in [2u16, 4, 8, 16] {
            for addr in ADDRESS_MODES {
                let s = Sampler::new(SamplerDescriptor::anisotropic(clamp).with_address_mode(addr))
                    .unwrap();
                let case = format!("clamp {clamp} {addr:?}");
                for len in [fps.len(), 64, 37] {
                    assert_batches_equal_single(&s, tex, &fps[..len], &case);
                }
            }
        }
        // The probe scratch is kept per thread between calls (`batch::anisotropic`): calls under
        // one border colour and then another, each after a call with more probes, must read the
        // new colour, not the last call's, and no stale probe of the longer call.
        for border in [
            BorderColor::OpaqueWhite,
            BorderColor::TransparentBlack,
            BorderColor::Custom([0.25, 0.5, 0.75, 1.0]),
        ] {
            let mut d =
                SamplerDescriptor::anisotropic(16).with_address_mode(AddressMode::ClampToBorder);
            d.border_color = border;
            let s = Sampler::new(d).unwrap();
            for len in [fps.len(), 37] {
                assert_batches_equal_single(&s, tex, &fps[..len], &format!("{border:?}"));
            }
        }
    }
}

/// Catmull-Rom interpolates: at every texel centre it returns the texel.
#[test]
fn catmull_rom_interpolates_at_centres() {
    let tex = noise_texture(8, 5, Format::Rgba32Float);
    let cr = FilterMode::Cubic(Cubic::CATMULL_ROM);
    for addr in ADDRESS_MODES {
        let s = sampler(cr, cr, MipmapFilterMode::None, addr);
        for j in 0..5 {
            for i in 0..8 {
                let fp = Footprint::point((i as f32 + 0.5) / 8.0, (j as f32 + 0.5) / 5.0);
                let got = s.sample(&tex, &fp);
                let want = tex.texel(0, i, j).unwrap();
                for k in 0..4 {
                    assert!(
                        (got[k] - want[k]).abs() < 1e-6,
                        "{addr:?} ({i},{j}) {got:?} {want:?}"
                    );
                }
            }
        }
    }
}

/// A footprint with the given lod on a square `size` texture (isotropic, axis-aligned).
fn at_lod(u: f32, v: f32, lod: f32, size: u32) -> Footprint {
    Footprint::isotropic(u, v, lod.exp2() / size as f32)
}

/// Trilinear is continuous in lod across every level boundary.
#[test]
fn trilinear_continuous_across_levels() {
    let tex = noise_texture(64, 64, Format::Rgba32Float);
    let s = sampler(
        FilterMode::Linear,
        FilterMode::Linear,
        MipmapFilterMode::Linear,
        AddressMode::Repeat,
    );
    for k in 1..6 {
        for p in 0..10 {
            let (u, v) = (noise(100 + p), noise(200 + p));
            let below = s.sample(&tex, &at_lod(u, v, k as f32 - 1e-4, 64));
            let above = s.sample(&tex, &at_lod(u, v, k as f32 + 1e-4, 64));
            for c in 0..4 {
                assert!(
                    (below[c] - above[c]).abs() < 2e-3,
                    "level {k}: {below:?} vs {above:?}"
                );
            }
        }
    }
}

/// mip_nearest switches level at the Vulkan rounding point lod = k + 1/2.
#[test]
fn mip_nearest_switches_at_vulkan_point() {
    let tex = noise_texture(64, 64, Format::Rgba32Float);
    let s = sampler(
        FilterMode::Linear,
        FilterMode::Linear,
        MipmapFilterMode::Nearest,
        AddressMode::Repeat,
    );
    let forced = |level: f32| {
        Sampler::new(SamplerDescriptor {
            lod_min_clamp: level,
            lod_max_clamp: level,
            ..*s.descriptor()
        })
        .unwrap()
    };
    let (u, v) = (0.37, 0.61);
    for k in 1..5 {
        let at_half = s.sample(&tex, &at_lod(u, v, k as f32 + 0.5, 64));
        let past_half = s.sample(&tex, &at_lod(u, v, k as f32 + 0.5 + 1e-3, 64));
        let level_k = forced(k as f32).sample(&tex, &at_lod(u, v, 0.0, 64));
        let level_k1 = forced(k as f32 + 1.0).sample(&tex, &at_lod(u, v, 0.0, 64));
        assert_eq!(at_half, level_k, "lod {k}.5 reads level {k}");
        assert_eq!(past_half, level_k1, "lod {k}.501 reads level {}", k + 1);
        assert_ne!(level_k, level_k1);
    }
}

/// Minifying a one-texel checkerboard 16x: trilinear gives the mean grey within 2 %, nearest aliases.
#[test]
fn minified_checkerboard_is_grey_with_trilinear_only() {
    let tex = Texture::from_fn(256, 256, Format::Rgba8Srgb, &Limits::default(), |i, j| {
        let c = ((i + j) % 2) as f32;
        [c, c, c, 1.0]
    })
    .unwrap();
    let tri = sampler(
        FilterMode::Linear,
        FilterMode::Linear,
        MipmapFilterMode::Linear,
        AddressMode::Repeat,
    );
    let near = sampler(
        FilterMode::Nearest,
        FilterMode::Nearest,
        MipmapFilterMode::None,
        AddressMode::Repeat,
    );
    let mut worst_tri = 0f32;
    let mut worst_near = 0f32;
    for y in 0..16 {
        for x in 0..16 {
            // 16 texels per pixel, plus an irrational offset so samples land anywhere in a texel.
            let fp = Footprint::isotropic(
                (x as f32 * 16.0 + 0.37) / 256.0,
                (y as f32 * 16.0 + 0.71) / 256.0,
                16.0 / 256.0,
            );
            worst_tri = worst_tri.max((tri.sample(&tex, &fp)[0] - 0.5).abs() / 0.5);
            worst_near = worst_near.max((near.sample(&tex, &fp)[0] - 0.5).abs() / 0.5);
        }
    }
    assert!(worst_tri < 0.02, "trilinear deviates {worst_tri}");
    assert!(
        worst_near > 0.9,
        "nearest should alias to black/white, deviates only {worst_near}"
    );
}

/// Texels read per sample, as each filter documents.
#[test]
fn texel_counts() {
    let tex = noise_texture(64, 64, Format::Rgba8Srgb);
    let cases = [
        (FilterMode::Nearest, MipmapFilterMode::None, 0.0, 1),
        (FilterMode::Linear, MipmapFilterMode::None, 0.0, 4),
        (
            FilterMode::Cubic(Cubic::CATMULL_ROM),
            MipmapFilterMode::None,
            0.0,
            16,
        ),
        (FilterMode::Linear, MipmapFilterMode::Nearest, 2.3, 4),
        (FilterMode::Linear, MipmapFilterMode::Linear, 2.3, 8),
        (FilterMode::Linear, MipmapFilterMode::Linear, 2.0, 4),
        // lod beyond the last level (6) holds the last level: one bilinear.
        (FilterMode::Linear, MipmapFilterMode::Linear, 9.5, 4),
    ];
    for (f, mip, lod, want) in cases {
        let s = sampler(f, f, mip, AddressMode::Repeat);
        let (c, n) = s.sample_counted(&tex, &at_lod(0.3, 0.4, lod, 64));
        assert_eq!(n, want, "{f:?} {mip:?} lod {lod}");
        assert_eq!(c, s.sample(&tex, &at_lod(0.3, 0.4, lod, 64)));
    }
}

/// The mean of every pyramid level equals the mean of level 0 (odd, even, non-square, 1xN, 1x1).
#[test]
fn pyramid_preserves_mean() {
    for (w, h) in [
        (64, 64),
        (37, 19),
        (5, 3),
        (1, 300),
        (300, 1),
        (1, 1),
        (2, 7),
        (129, 130),
    ] {
        let tex = noise_texture(w, h, Format::Rgba32Float);
        let m0 = tex.level_mean(0);
        assert_eq!(
            tex.levels().last().map(|l| (l.width, l.height)),
            Some((1, 1))
        );
        for k in 1..tex.levels().len() {
            let m = tex.level_mean(k);
            for c in 0..4 {
                assert!(
                    (m[c] - m0[c]).abs() < 1e-5,
                    "{w}x{h} level {k} channel {c}: {} vs {}",
                    m[c],
                    m0[c]
                );
            }
        }
        // 8-bit sRGB: the mean holds up to re-quantisation of each level.
        let tex8 = noise_texture(w, h, Format::Rgba8Srgb);
        let m0 = tex8.level_mean(0);
        for k in 1..tex8.levels().len() {
            let m = tex8.level_mean(k);
            for c in 0..3 {
                assert!(
                    (m[c] - m0[c]).abs() < 4e-3,
                    "{w}x{h} level {k}: {} vs {}",
                    m[c],
                    m0[c]
                );
            }
        }
    }
}

/// The pyramid costs about 4/3 of level 0 and its levels follow max(1, W >> k).
#[test]
fn pyramid_memory_and_sizes() {
    let tex = noise_texture(1024, 512, Format::Rgba8Srgb);
    let level0 = 1024 * 512 * 4;
    let ratio = tex.pyramid_bytes() as f64 / level0 as f64;
    assert!((ratio - 4.0 / 3.0).abs() < 0.01, "ratio {ratio}");
    let sizes: Vec<_> = tex.levels().iter().map(|l| (l.width, l.height)).collect();
    assert_eq!(sizes[..3], [(1024, 512), (512, 256), (256, 128)]);
    assert_eq!(sizes[9..], [(2, 1), (1, 1)]);
}

/// NaN/inf/huge coordinates and derivatives, tiny textures: no panic, finite results.
#[test]
fn hostile_inputs_never_panic() {
    let specials = [
        0.0,
        0.5,
        -0.5,
        1e9,
        -1e9,
        3.4e38,
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        1e-30,
    ];
    for (w, h) in [(1, 1), (1, 17), (17, 1), (16, 16)] {
        let tex = noise_texture(w, h, Format::Rgba8Srgb);
        for s in every_sampler(BorderColor::OpaqueWhite) {
            for &a in &specials {
                for &b in &specials {
                    let fps = [
                        Footprint {
                            u: a,
                            v: b,
                            dudx: 0.01,
                            dudy: 0.0,
                            dvdx: 0.0,
                            dvdy: 0.01,
                        },
                        Footprint {
                            u: 0.3,
                            v: 0.3,
                            dudx: a,
                            dudy: b,
                            dvdx: b,
                            dvdy: a,
                        },
                    ];
                    for fp in fps {
                        let c = s.sample(&tex, &fp);
                        assert!(
                            c.iter().all(|x| x.is_finite()),
                            "{:?} {fp:?} {c:?}",
                            s.descriptor()
                        );
                    }
                }
            }
        }
    }
}

/// Non-finite derivatives select the coarsest level; zero derivatives select level 0.
#[test]
fn degenerate_derivatives_pick_levels() {
    let tex = noise_texture(32, 32, Format::Rgba32Float);
    let s = sampler(
        FilterMode::Linear,
        FilterMode::Linear,
        MipmapFilterMode::Linear,
        AddressMode::Repeat,
    );
    let nan = Footprint {
        dudx: f32::NAN,
        ..Footprint::point(0.2, 0.2)
    };
    let coarsest = tex.texel(5, 0, 0).unwrap();
    let got = s.sample(&tex, &nan);
    for c in 0..4 {
        assert!((got[c] - coarsest[c]).abs() < 1e-6);
    }
    let bilinear0 = sampler(
        FilterMode::Linear,
        FilterMode::Linear,
        MipmapFilterMode::None,
        AddressMode::Repeat,
    );
    assert_eq!(
        s.sample(&tex, &Footprint::point(0.2, 0.2)),
        bilinear0.sample(&tex, &Footprint::point(0.2, 0.2))
    );
}

/// Descriptor validation happens once, with the offending values in the error.
#[test]
fn invalid_descriptors_are_rejected() {
    let bad = [
        SamplerDescriptor {
            lod_min_clamp: 3.0,
            lod_max_clamp: 1.0,
            ..Default::default()
        },
        SamplerDescriptor {
            lod_min_clamp: f32::NAN,
            ..Default::default()
        },
        SamplerDescriptor {
            lod_min_clamp: -1.0,
            ..Default::default()
        },
        SamplerDescriptor {
            lod_bias: f32::INFINITY,
            ..Default::default()
        },
        SamplerDescriptor {
            anisotropy_clamp: 0,
            ..Default::default()
        },
        SamplerDescriptor {
            anisotropy_clamp: 65,
            ..Default::default()
        },
        SamplerDescriptor {
            anisotropy_clamp: 4,
            ..Default::default()
        },
        SamplerDescriptor {
            mag_filter: FilterMode::Cubic(Cubic {
                b: f32::NAN,
                c: 0.0,
            }),
            ..Default::default()
        },
        // Found by the `sampler` fuzz target: finite but huge parameters made samples infinite.
        SamplerDescriptor {
            mag_filter: FilterMode::Cubic(Cubic {
                b: 5.7646075e17,
                c: -4.519031e33,
            }),
            ..Default::default()
        },
        SamplerDescriptor {
            min_filter: FilterMode::Cubic(Cubic { b: 0.0, c: 2.5 }),
            ..Default::default()
        },
    ];
    for d in bad {
        assert!(Sampler::new(d).is_err(), "{d:?} should be rejected");
    }
    let e = Sampler::new(SamplerDescriptor {
        lod_min_clamp: 3.0,
        lod_max_clamp: 1.0,
        ..Default::default()
    })
    .unwrap_err();
    assert!(e.to_string().contains("lod_min_clamp = 3"), "{e}");
    assert!(matches!(
        Filter::from_lab_mode(0),
        Err(TextureError::UnknownLabMode(0))
    ));
    assert!(matches!(
        Filter::from_lab_mode(99),
        Err(TextureError::UnknownLabMode(99))
    ));
}

/// The lab's modes 1-4.
#[test]
fn lab_modes() {
    let m = |n| {
        Filter::from_lab_mode(n)
            .map(SamplerDescriptor::from)
            .unwrap()
    };
    assert_eq!(
        (m(1).min_filter, m(1).mipmap_filter),
        (FilterMode::Nearest, MipmapFilterMode::None)
    );
    assert_eq!(
        (m(2).min_filter, m(2).mipmap_filter),
        (FilterMode::Linear, MipmapFilterMode::None)
    );
    assert_eq!(
        (m(3).min_filter, m(3).mipmap_filter),
        (FilterMode::Linear, MipmapFilterMode::Nearest)
    );
    assert_eq!(
        (m(4).min_filter, m(4).mipmap_filter),
        (FilterMode::Linear, MipmapFilterMode::Linear)
    );
}

fn png_bytes(w: u32, h: u32, rgba: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(rgba, w, h, image::ExtendedColorType::Rgba8)
        .unwrap();
    out
}
use image::ImageEncoder;

/// PNG decoding keeps every byte; sRGB/linear tagging decides the decode.
#[test]
fn png_round_trip() {
    let rgba: Vec<u8> = (0..3 * 2 * 4).map(|k| (k * 10) as u8).collect();
    let png = png_bytes(3, 2, &rgba);
    let lin = Texture::decode(&png, ColorSpace::Linear, &Limits::default()).unwrap();
    assert_eq!(
        (lin.width(), lin.height(), lin.format()),
        (3, 2, Format::Rgba8Unorm)
    );
    assert_eq!(
        lin.texel(0, 1, 0).unwrap(),
        [40.0 / 255.0, 50.0 / 255.0, 60.0 / 255.0, 70.0 / 255.0]
    );
    let srgb = Texture::decode(&png, ColorSpace::Srgb, &Limits::default()).unwrap();
    let t = srgb.texel(0, 1, 0).unwrap();
    assert!((t[0] - texel_texture::base::color::srgb_to_linear(40.0 / 255.0)).abs() < 1e-6);
    assert_eq!(t[3], 70.0 / 255.0, "alpha stays linear");
}

/// Corrupt, truncated, empty and oversized inputs give typed errors.
#[test]
fn bad_images_are_errors() {
    let png = png_bytes(4, 4, &[200; 64]);
    let truncated = &png[..png.len() / 2];
    assert!(matches!(
        Texture::decode(truncated, ColorSpace::Srgb, &Limits::default()),
        Err(TextureError::Decode(_))
    ));
    assert!(Texture::decode(b"not an image at all", ColorSpace::Srgb, &Limits::default()).is_err());
    assert!(Texture::decode(&[], ColorSpace::Srgb, &Limits::default()).is_err());
    let small = Limits {
        max_dimension: 2,
        ..Limits::default()
    };
    assert!(Texture::decode(&png, ColorSpace::Srgb, &small).is_err());
    assert!(matches!(
        Texture::from_rgba8(0, 4, vec![], ColorSpace::Srgb, &Limits::default()),
        Err(TextureError::EmptySize {
            width: 0,
            height: 4
        })
    ));
    assert!(matches!(
        Texture::from_rgba8(2, 2, vec![[0; 4]; 3], ColorSpace::Srgb, &Limits::default()),
        Err(TextureError::DataLength {
            expected: 4,
            got: 3,
            ..
        })
    ));
    // Nothing is allocated before the limits are checked: a 16384^2 float texture is refused at 1 GiB.
    let tight = Limits {
        max_bytes: 1 << 30,
        ..Limits::default()
    };
    assert!(matches!(
        Texture::from_fn(16384, 16384, Format::Rgba32Float, &tight, |_, _| [0.0; 4]),
        Err(TextureError::OverMemoryLimit { .. })
    ));
    assert!(matches!(
        Texture::from_fn(
            20000,
            1,
            Format::Rgba8Srgb,
            &Limits::default(),
            |_, _| [0.0; 4]
        ),
        Err(TextureError::TooLarge { max: 16384, .. })
    ));
    // A PNG header claiming 100000 x 100000 is refused by the decoder's limits.
    let mut huge = png.clone();
    huge[16..20].copy_from_slice(&100_000u32.to_be_bytes());
    huge[20..24].copy_from_slice(&100_000u32.to_be_bytes());
    assert!(Texture::decode(&huge, ColorSpace::Srgb, &Limits::default()).is_err());
}

/// A missing file is an I/O error naming nothing in particular but never panicking.
#[test]
fn missing_file_is_io_error() {
    assert!(matches!(
        Texture::load(
            "/definitely/not/here.png",
            ColorSpace::Srgb,
            &Limits::default()
        ),
        Err(TextureError::Io(_))
    ));
}

/// OpenEXR (float) images decode to linear RGBA32F, ignoring the colour-space tag.
#[test]
fn exr_round_trip() {
    let pixels: Vec<f32> = (0..4 * 3 * 2).map(|k| k as f32 * 0.37 - 1.0).collect();
    let mut bytes = std::io::Cursor::new(Vec::new());
    image::codecs::openexr::OpenExrEncoder::new(&mut bytes)
        .write_image(
            bytemuck_f32(&pixels).as_slice(),
            3,
            2,
            image::ExtendedColorType::Rgba32F,
        )
        .unwrap();
    let tex = Texture::decode(bytes.get_ref(), ColorSpace::Srgb, &Limits::default()).unwrap();
    assert_eq!(
        (tex.width(), tex.height(), tex.format()),
        (3, 2, Format::Rgba32Float)
    );
    for j in 0..2 {
        for i in 0..3 {
            let k = 4 * (j * 3 + i) as usize;
            assert_eq!(
                tex.texel(0, i, j).unwrap(),
                [pixels[k], pixels[k + 1], pixels[k + 2], pixels[k + 3]]
            );
        }
    }
}

/// Native-endian bytes of `f32`s, as image-rs's encoders take them.
fn bytemuck_f32(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_ne_bytes()).collect()
}

/// Within the accepted range (`|B|, |C| <= 2`) a cubic sample stays within (7/3)^2 times the
/// largest texel magnitude, the bound `filter::MAX_CUBIC_PARAMETER` documents; checked at the
/// range's corners on a checkerboard, the worst case for negative lobes.
#[test]
fn cubic_overshoot_is_bounded_at_the_parameter_limits() {
    let tex = Texture::from_fn(8, 8, Format::Rgba32Float, &Limits::default(), |i, j| {
        let v = ((i + j) % 2) as f32;
        [v, v, v, 1.0]
    })
    .unwrap();
    let m = texel_texture::base::filter::MAX_CUBIC_PARAMETER;
    for (b, c) in [(m, m), (-m, m), (m, -m), (-m, -m), (0.0, 0.5)] {
        let s = Sampler::new(SamplerDescriptor {
            mag_filter: FilterMode::Cubic(Cubic { b, c }),
            ..SamplerDescriptor::default().with_address_mode(AddressMode::Repeat)
        })
        .unwrap();
        for k in 0..64 {
            let (u, v) = (k as f32 / 64.0 + 0.003, (k * 7 % 64) as f32 / 64.0 + 0.011);
            let r = s.sample(&tex, &Footprint::point(u, v));
            assert!(
                r[0].is_finite() && r[0].abs() <= (7.0f32 / 3.0).powi(2),
                "{b} {c}: {r:?}"
            );
        }
    }
}

/// Regression (fuzz target `sampler`): a summed-area box far beyond a clamped edge (x ~ 2e8,
/// y ~ -3e9) cancelled its huge prefix terms to a mean of 2048 on a texture in `[0, 1]`. Beyond
/// the edge the extension is constant, so the mean is the corner texel.
#[test]
fn summed_area_far_beyond_clamped_edges_is_the_edge_texel() {
    use texel_texture::SummedAreaTable;
    let tex = Texture::from_fn(14, 163, Format::Rgba32Float, &Limits::default(), |i, j| {
        [
            (i as f32 * 0.37 + j as f32 * 0.11).fract(),
            (j as f32 * 0.013).fract(),
            0.5,
            1.0,
        ]
    })
    .unwrap();
    let t = SummedAreaTable::build(&tex).unwrap();
    let corner = tex.texel(0, 13, 162).unwrap();
    for mode in [AddressMode::ClampToEdge, AddressMode::MirrorClampToEdge] {
        let (x, y) = (
            2.3e8,
            if mode == AddressMode::ClampToEdge {
                2.7e9
            } else {
                -2.7e9
            },
        );
        let m = t.box_mean(
            [x, x + 1.0],
            [y, y + 1.0],
            &Address::new(mode, mode, BorderColor::TransparentBlack),
        );
        for c in 0..4 {
            assert!(
                (m[c] - f64::from(corner[c])).abs() < 1e-9,
                "{mode:?}: {m:?} vs {corner:?}"
            );
        }
    }
}

/// Regression (fuzz target `image_decode`): this 1.5 KB JPEG makes zune-jpeg 0.5.15 panic in its
/// AVX2 IDCT (`Option::unwrap()` on `None` storing a block of an unusual sampling layout). The
/// panic is caught and reported as an error.
#[test]
fn a_decoder_panic_is_an_error() {
    let bytes = include_bytes!("data/zune-avx2-idct-panic.jpg");
    match Texture::decode(bytes, ColorSpace::Srgb, &Limits::default()) {
        Err(TextureError::DecoderFailed(msg)) => assert!(!msg.is_empty()),
        // A decoder version (or a CPU without AVX2) that handles the file is fine too: the point
        // is that decoding returns.
        Err(e) => assert!(e.to_string().contains("decode"), "{e}"),
        Ok(t) => assert!(t.width() > 0),
    }
}

/// A JPEG is checked by walking its segments to the end-of-image marker: data after EOI (a motion
/// photo's video, which may contain 0xFFDA) is ignored, a cut anywhere before EOI is an error.
#[test]
fn jpeg_completeness_walks_the_segments() {
    // Detailed enough that its scan data is most of the file.
    let img = image::RgbImage::from_fn(200, 120, |x, y| {
        image::Rgb([
            (x * 37 % 251) as u8,
            (y * 53 % 241) as u8,
            ((x ^ y) * 7) as u8,
        ])
    });
    let mut jpeg = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, 85)
        .encode_image(&img)
        .unwrap();
    let limits = Limits::default();
    assert!(Texture::decode(&jpeg, ColorSpace::Srgb, &limits).is_ok());
    let mut trailing = jpeg.clone();
    trailing.extend_from_slice(b"\xFF\xDA\x00\x08ftypmp42 and more video bytes");
    assert!(Texture::decode(&trailing, ColorSpace::Srgb, &limits).is_ok());
    assert!(jpeg.len() > 4000, "{}", jpeg.len());
    for cut in [jpeg.len() - 2, jpeg.len() / 2] {
        let e = Texture::decode(&jpeg[..cut], ColorSpace::Srgb, &limits).unwrap_err();
        assert!(
            e.to_string().contains("before its end-of-image marker"),
            "{cut}: {e}"
        );
    }
    // Cut inside the headers, the decoder's own header parser refuses it first.
    assert!(Texture::decode(&jpeg[..30], ColorSpace::Srgb, &limits).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    /// The stored-bytes span (`SpanKind::Stored`) is, for every single-texel sampler (nearest, with no or nearest
    /// mipmaps) under every address mode and border colour, the bytes the texture's own format
    /// encodes `sample` to, and for texels inside the texture a code whose decoding is `sample`
    /// bit for bit. Other samplers and float textures are refused with nothing written.
    #[test]
    fn stored_bytes_are_the_encoded_samples(
        fps in proptest::collection::vec(footprint_strategy(), 1..150),
        (w, h) in prop_oneof![Just((64u32, 32u32)), Just((37, 5)), Just((1, 9))],
    ) {
        let borders = [
            BorderColor::TransparentBlack,
            BorderColor::OpaqueWhite,
            BorderColor::Custom([0.3, 0.7, 0.05, 0.5]),
            BorderColor::Custom([2.0, -1.0, f32::NAN, 0.25]),
        ];
        let mut out = vec![[7u8; 4]; fps.len()];
        for format in [Format::Rgba8Srgb, Format::Rgba8Unorm, Format::Rgba32Float] {
            let tex = noise_texture(w, h, format);
            let table = match format {
                Format::Rgba8Srgb => texel_texture::base::color::srgb_table(),
                _ => texel_texture::base::color::unorm8_table(),
            };
            for border in borders {
                for s in every_sampler(border) {
                    let d = s.descriptor();
                    let one = d.min_filter == FilterMode::Nearest
                        && d.mag_filter == FilterMode::Nearest
                        && d.mipmap_filter != MipmapFilterMode::Linear;
                    out.fill([7; 4]);
                    let took = stored_bytes(&s, &tex, &fps, &mut out);
                    prop_assert_eq!(took, one && format != Format::Rgba32Float);
                    if !took {
                        prop_assert!(out.iter().all(|&o| o == [7; 4]));
                        continue;
                    }
                    for (f, &o) in fps.iter().zip(&out) {
                        let c = s.sample(&tex, f);
                        let encoded = match format {
                            Format::Rgba8Srgb => texel_texture::base::color::rgba_to_srgb8(c),
                            _ => texel_texture::base::color::rgba_to_unorm8(c),
                        };
                        prop_assert_eq!(o, encoded, "{:?} {:?} {:?}", d, f, format);
                        let decoded = [
                            table[o[0] as usize],
                            table[o[1] as usize],
                            table[o[2] as usize],
                            f32::from(o[3]) / 255.0,
                        ];
                        // Texels and the two borders that 8 bits represent exactly decode
                        // back to the sample bit for bit (a custom border only encodes).
                        if !matches!(border, BorderColor::Custom(_)) {
                            prop_assert_eq!(decoded.map(f32::to_bits), c.map(f32::to_bits));
                        }
                    }
                }
            }
        }
    }
}

/// The fixed-point span blends its bilinear quads in eight lanes with an AVX2 `Lanes` token and
/// in four without: the same bytes, for every core sampler on a linear 8-bit texture, over
/// blocks of 64 footprints that share their derivatives (so that whole chunks sit in one level or
/// one pair, where the run kernel takes them), from magnified to minified by 8, inside the
/// texture and across its edges.
#[test]
fn fixed8_spans_are_the_same_bytes_in_every_lanes() {
    let wide = Lanes::detect();
    if !wide.is_wide() {
        println!("skipped: this CPU has no AVX2 (x86-64-v3); only the four-lane kernel runs");
        return;
    }
    let tex = noise_texture(64, 32, Format::Rgba8Unorm);
    let fps: Vec<Footprint> = (0..64 * 24)
        .map(|k| {
            let (u, v) = spread(k);
            let block = k / 64;
            // Blocks 0..12 inside the texture's middle, 12..24 across its edges.
            let (u, v) = if block < 12 {
                (0.2 + 0.6 * u, 0.2 + 0.6 * v)
            } else {
                (1.4 * u - 0.2, 1.4 * v - 0.2)
            };
            let d = 0.004 * (1 + block % 12) as f32;
            Footprint {
                u,
                v,
                dudx: d,
                dvdx: 0.25 * d,
                dudy: -0.1 * d,
                dvdy: 1.5 * d,
            }
        })
        .collect();
    let wants = Wants {
        stored_bytes: false,
        fixed8: true,
    };
    let mut compared = 0;
    for s in every_sampler(BorderColor::Custom([0.3, 0.7, 0.05, 0.5])) {
        let bound = s.bind(&tex, wants);
        if bound.kind() != SpanKind::Fixed8 {
            continue;
        }
        let (mut four, mut eight) = (vec![[0u8; 4]; fps.len()], vec![[1u8; 4]; fps.len()]);
        bound.sample_span(Lanes::scalar(), &fps, &mut [], &mut four);
        bound.sample_span(wide, &fps, &mut [], &mut eight);
        assert!(four == eight, "{:?}", s.descriptor());
        compared += 1;
    }
    // Nearest and linear, three mipmap modes, five address modes.
    assert_eq!(compared, 2 * 3 * 5);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    /// The fixed-point span (`SpanKind::Fixed8`, GPU-style 8-bit weights, every blend rounded to
    /// a code) stays within a stated distance of the exact sample's unorm8 encoding: nearest
    /// without mip blending is exact; one bilinear level at most 2 codes (each of the two weights'
    /// quantisation moves the value by at most `255 / 512` of a code, the row blends' rounding and
    /// the blend of the rows' each by half, the exact path's encoding by half: 2.5, so 2 between
    /// codes); a mip blend of two levels at most 3 (2 per level, `255 / 512` for the mip weight,
    /// half for its rounding, half for the encoding). It applies to the core filters on
    /// `Rgba8Unorm` only.
    #[test]
    fn fixed8_is_within_its_bound_of_exact(
        fps in proptest::collection::vec(footprint_strategy(), 1..150),
        (w, h) in prop_oneof![Just((64u32, 32u32)), Just((37, 5)), Just((1, 9))],
    ) {
        let mut out = vec![[7u8; 4]; fps.len()];
        for format in [Format::Rgba8Srgb, Format::Rgba8Unorm, Format::Rgba32Float] {
            let tex = noise_texture(w, h, format);
            for border in [BorderColor::OpaqueWhite, BorderColor::Custom([0.3, 0.7, 0.05, 0.5])] {
                for s in every_sampler(border) {
                    let d = *s.descriptor();
                    let core = matches!(d.min_filter, FilterMode::Nearest | FilterMode::Linear);
                    let applies = core && format == Format::Rgba8Unorm;
                    prop_assert_eq!(s.bind(&tex, Wants { fixed8: true, ..Wants::default() }).kind() == SpanKind::Fixed8, applies);
                    out.fill([7; 4]);
                    prop_assert_eq!(fixed8_codes(&s, &tex, &fps, &mut out), applies);
                    if !applies {
                        prop_assert!(out.iter().all(|&o| o == [7; 4]));
                        continue;
                    }
                    let bound = match (d.min_filter, d.mipmap_filter) {
                        (FilterMode::Nearest, MipmapFilterMode::Linear) => 1,
                        (FilterMode::Nearest, _) => 0,
                        (_, MipmapFilterMode::Linear) => 3,
                        _ => 2,
                    };
                    for (f, o) in fps.iter().zip(&out) {
                        let exact = texel_texture::base::color::rgba_to_unorm8(s.sample(&tex, f));
                        for c in 0..4 {
                            let diff = (i32::from(o[c]) - i32::from(exact[c])).abs();
                            prop_assert!(diff <= bound, "{:?} {:?}: {:?} vs {:?}", d, f, o, exact);
                        }
                    }
                }
            }
        }
    }
}

/// `Sampler::uses_derivatives`' contract: where it is `false` (no mipmaps, `mag_filter ==
/// min_filter`) no sampling path reads a footprint's derivative fields, so a caller may leave any
/// values there (or, as lanes, give none). Footprints whose
/// derivatives are NaN, infinite, huge or tiny sample bit for bit as with zero derivatives, through
/// `sample`, `sample_batch` (both quad kernels), the stored-bytes and fixed-point spans,
/// for every such sampler (nearest, bilinear and the cubic filters, every address mode) on every
/// texel format. Samplers that do use derivatives are checked to be told apart.
#[test]
fn lod_free_samplers_never_read_derivatives() {
    let junk = [
        f32::NAN,
        f32::INFINITY,
        -f32::INFINITY,
        1e30,
        -3.5,
        1e-30,
        0.75,
    ];
    let zeroed: Vec<Footprint> = (0..150)
        .map(|k| {
            let (u, v) = spread(k);
            Footprint::point(u * 3.0 - 1.0, v * 2.0 - 0.5)
        })
        .collect();
    let junked: Vec<Footprint> = zeroed
        .iter()
        .enumerate()
        .map(|(k, f)| Footprint {
            dudx: junk[k % 7],
            dudy: junk[(k + 1) % 7],
            dvdx: junk[(k + 3) % 7],
            dvdy: junk[(k + 5) % 7],
            ..*f
        })
        .collect();
    let mut lod_free = 0;
    for format in [Format::Rgba8Srgb, Format::Rgba8Unorm, Format::Rgba32Float] {
        let tex = noise_texture(37, 21, format);
        for s in every_sampler(BorderColor::OpaqueWhite) {
            if s.uses_derivatives() {
                assert_ne!(s.descriptor().mipmap_filter, MipmapFilterMode::None);
                continue;
            }
            lod_free += 1;
            let case = format!("{format:?} {:?}", s.descriptor());
            for (z, j) in zeroed.iter().zip(&junked) {
                let (a, b) = (s.sample(&tex, z), s.sample(&tex, j));
                assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits), "sample {case}");
            }
            for lanes in [Lanes::scalar(), Lanes::detect()] {
                let mut a = vec![[0.0; 4]; zeroed.len()];
                let mut b = a.clone();
                s.sample_batch_lanes(lanes, &tex, &zeroed, &mut a);
                s.sample_batch_lanes(lanes, &tex, &junked, &mut b);
                assert_eq!(bits(&a), bits(&b), "sample_batch {case}");
            }
            let mut a = vec![[0u8; 4]; zeroed.len()];
            let mut b = a.clone();
            let took = stored_bytes(&s, &tex, &zeroed, &mut a);
            assert_eq!(took, stored_bytes(&s, &tex, &junked, &mut b), "{case}");
            assert_eq!(a, b, "stored bytes {case}");
            let took = fixed8_codes(&s, &tex, &zeroed, &mut a);
            assert_eq!(took, fixed8_codes(&s, &tex, &junked, &mut b), "{case}");
            assert_eq!(a, b, "fixed8 {case}");
        }
    }
    // Nearest, bilinear and three cubic filters under five address modes, three formats.
    assert_eq!(lod_free, 3 * 5 * 5);
}

/// Footprints given as lanes ([`FootprintLanes`]) sample as the same footprints given as structs,
/// through every batched entry (`sample_batch`, both quad kernels, the stored-bytes and
/// fixed-point spans), for every sampler (the core filters under every address mode, and the
/// anisotropic, EWA, ripmap and summed-area filters) on every texel format, over several chunks
/// and a short tail (150 footprints); and lanes without derivatives
/// ([`FootprintLanes::points`]) as structs with zero derivatives.
#[test]
fn lanes_sample_as_structs() {
    let fps: Vec<Footprint> = (0..150)
        .map(|k| {
            let (u, v) = spread(k);
            let d = [0.0, 1e-3, 0.02, 0.3][k % 4];
            Footprint {
                u: u * 3.0 - 1.0,
                v: v * 2.0 - 0.5,
                dudx: d,
                dudy: -0.5 * d,
                dvdx: 0.25 * d,
                dvdy: 1.5 * d,
            }
        })
        .collect();
    let points: Vec<Footprint> = fps.iter().map(|f| Footprint::point(f.u, f.v)).collect();
    let (u, v, d) = lanes_of(&fps);
    let lanes = FootprintLanes::new(&u, &v, [&d[0], &d[1], &d[2], &d[3]]);
    let point_lanes = FootprintLanes::points(&u, &v);
    let mut samplers = every_sampler(BorderColor::OpaqueWhite);
    for d in [
        SamplerDescriptor::anisotropic(16),
        SamplerDescriptor::minification(FilterMode::Ewa),
        SamplerDescriptor::minification(FilterMode::Ripmap),
        SamplerDescriptor::minification(FilterMode::SummedArea),
    ] {
        samplers.push(Sampler::new(d.with_address_mode(AddressMode::Repeat)).unwrap());
    }
    let n = fps.len();
    for format in [Format::Rgba8Srgb, Format::Rgba8Unorm, Format::Rgba32Float] {
        let tex = noise_texture(37, 21, format);
        for s in &samplers {
            let case = format!("{format:?} {:?}", s.descriptor());
            for lanes_kernel in [Lanes::scalar(), Lanes::detect()] {
                for (structs, as_lanes) in [(&fps, lanes), (&points, point_lanes)] {
                    let mut a = vec![[0.0; 4]; n];
                    let mut b = vec![[1.0; 4]; n];
                    s.sample_batch_lanes(lanes_kernel, &tex, structs, &mut a);
                    s.sample_batch_lanes(lanes_kernel, &tex, as_lanes, &mut b);
                    assert_eq!(bits(&a), bits(&b), "sample_batch {case}");
                }
            }
            for (structs, as_lanes) in [(&fps, lanes), (&points, point_lanes)] {
                let mut a = vec![[0u8; 4]; n];
                let mut b = vec![[1u8; 4]; n];
                let took = stored_bytes(s, &tex, structs, &mut a);
                assert_eq!(took, stored_bytes(s, &tex, as_lanes, &mut b), "{case}");
                if took {
                    assert_eq!(a, b, "stored bytes {case}");
                }
                let took = fixed8_codes(s, &tex, structs, &mut a);
                assert_eq!(took, fixed8_codes(s, &tex, as_lanes, &mut b), "{case}");
                if took {
                    assert_eq!(a, b, "fixed8 {case}");
                }
            }
        }
    }
}

/// A lanes batch whose length differs from `out`'s is a programming error: a panic that says so,
/// as for structs.
#[test]
#[should_panic(expected = "differ in length")]
fn lanes_longer_than_out_panic() {
    let tex = noise_texture(8, 8, Format::Rgba8Unorm);
    let s = sampler(
        FilterMode::Linear,
        FilterMode::Linear,
        MipmapFilterMode::None,
        AddressMode::Repeat,
    );
    let (u, v) = ([0.25f32; 5], [0.5f32; 5]);
    let mut out = [[0.0f32; 4]; 4];
    s.sample_batch(&tex, FootprintLanes::points(&u, &v), &mut out);
}

/// Float texels at the edge of their range (`±MAX_TEXEL`) filter to finite values within it (a
/// Catmull-Rom bicubic's overshoot aside), for
/// every filter and aniso64, on footprints from magnified to anisotropy 64 (EWA's and the probes'
/// sums of many such texels stay finite); beyond the range a texture is refused, naming the
/// texel, and `replace_non_finite` clamps to the range.
#[test]
fn float_texels_at_the_range_edge_filter_to_finite_values() {
    use texel_texture::{replace_non_finite, Filter, MAX_TEXEL};
    let m = MAX_TEXEL;
    // Constant, and noise of the two extremes (every filter's sum sees both signs).
    let constant = vec![[m; 4]; 64 * 64];
    let extremes: Vec<[f32; 4]> = (0..64 * 64u64)
        .map(|k| {
            let c = |s| if noise(4 * k + s) < 0.5 { -m } else { m };
            [c(0), c(1), c(2), m]
        })
        .collect();
    let mut descriptors: Vec<(String, SamplerDescriptor)> = Filter::ALL
        .iter()
        .map(|f| {
            let d = f.descriptor(AddressMode::Repeat, AddressMode::Repeat);
            (f.name().to_string(), d)
        })
        .collect();
    descriptors.push((
        "aniso64".into(),
        SamplerDescriptor {
            anisotropy_clamp: 64,
            ..Filter::Trilinear.descriptor(AddressMode::Repeat, AddressMode::Repeat)
        },
    ));
    let axes = [
        (0.1f32, 0.1f32),
        (1.0, 1.0),
        (8.0, 1.0),
        (64.0, 1.0),
        (64.0, 0.25),
    ];
    let footprints = rotated_footprints(&axes, 16, 0.4, |x| x);
    for (texels, name) in [(constant, "constant"), (extremes, "extremes")] {
        let tex = Texture::from_rgba32f(64, 64, texels, &Limits::default()).unwrap();
        for (filter, d) in &descriptors {
            let s = Sampler::new(*d).unwrap();
            let mut batch = vec![[0.0; 4]; footprints.len()];
            s.sample_batch(&tex, &footprints, &mut batch);
            // Catmull-Rom's weights have absolute values summing to at most 1.25 an axis.
            let bound = m * (1.0 + 1e-5) * if filter == "bicubic" { 1.5625 } else { 1.0 };
            for (fp, b) in footprints.iter().zip(&batch) {
                let one = s.sample(&tex, fp);
                for c in one.iter().chain(b) {
                    assert!(
                        c.is_finite() && c.abs() <= bound,
                        "{name} {filter} {fp:?}: {c}"
                    );
                }
                if name == "constant" && filter != "bicubic" {
                    assert!(((one[0] - m) / m).abs() <= 1e-5, "{filter} {fp:?}: {one:?}");
                }
            }
        }
    }
    // Beyond the range: refused, naming the texel; replaced by the range's edge when asked.
    let mut texels = vec![[1.0f32; 4]; 16];
    texels[5][2] = 3e38;
    match Texture::from_rgba32f(4, 4, texels.clone(), &Limits::default()) {
        Err(e @ TextureError::TexelOutOfRange { x: 1, y: 1, .. }) => {
            let msg = e.to_string();
            assert!(
                msg.contains("channel B is 3e38") && msg.contains("--sanitize"),
                "{msg}"
            );
        }
        other => panic!("{other:?}"),
    }
    texels[6][0] = f32::NAN;
    texels[7][1] = -f32::MAX;
    assert_eq!(replace_non_finite(&mut texels), 3);
    assert_eq!((texels[5][2], texels[6][0], texels[7][1]), (m, 0.0, -m));
    assert!(Texture::from_rgba32f(4, 4, texels, &Limits::default()).is_ok());
}

/// A decoded float copy ([`Texture::to_float`]) samples bit for bit as its 8-bit original: every
/// named filter (ripmap and summed-area table included, built on each texture), every address
/// mode, sRGB and unorm codes, a power-of-two and an odd size, footprints from magnified to
/// 64:1, through the one-sample and the batched paths.
#[test]
fn float_copies_sample_as_their_8bit_originals() {
    let axes = [
        (0.3f32, 0.3f32),
        (1.5, 1.0),
        (6.0, 2.0),
        (16.0, 1.0),
        (64.0, 1.0),
        (40.0, 13.0),
    ];
    // Some centres outside [0, 1) so that the address modes matter.
    let footprints = rotated_footprints(&axes, 24, 0.37, |x| x * 1.6 - 0.3);
    for format in [Format::Rgba8Srgb, Format::Rgba8Unorm] {
        for (w, h) in [(64, 64), (37, 53)] {
            let stored = noise_texture(w, h, format);
            let float = stored.to_float().unwrap();
            assert_eq!(float.format(), Format::Rgba32Float);
            assert_eq!(float.source_format(), format);
            assert_eq!(float.pyramid_bytes(), 4 * stored.pyramid_bytes());
            for mode in ADDRESS_MODES {
                for filter in texel_texture::Filter::ALL {
                    let s = Sampler::new(filter.descriptor(mode, mode)).unwrap();
                    let (mut a, mut b) = (
                        vec![[0.0; 4]; footprints.len()],
                        vec![[0.0; 4]; footprints.len()],
                    );
                    s.sample_batch(&stored, &footprints, &mut a);
                    s.sample_batch(&float, &footprints, &mut b);
                    for ((fp, x), y) in footprints.iter().zip(&a).zip(&b) {
                        let what = format!("{format:?} {w}x{h} {mode:?} {}", filter.name());
                        assert_eq!(x.map(f32::to_bits), y.map(f32::to_bits), "{what} {fp:?}");
                        let (p, q) = (s.sample(&stored, fp), s.sample(&float, fp));
                        assert_eq!(p.map(f32::to_bits), q.map(f32::to_bits), "{what} {fp:?}");
                    }
                }
            }
        }
    }
    // Past the limits the copy is refused, not allocated: 4 bytes a texel fit, 16 do not.
    let limits = Limits {
        max_bytes: 50_000,
        ..Limits::default()
    };
    let small = Texture::from_fn(64, 64, Format::Rgba8Unorm, &limits, |_, _| [0.5; 4]).unwrap();
    assert!(small.to_float().is_err());
    // A float texture is copied as it is.
    let f = noise_texture(9, 7, Format::Rgba32Float);
    let g = f.to_float().unwrap();
    assert_eq!(g.source_format(), Format::Rgba32Float);
    for k in 0..f.levels().len() {
        assert_eq!(f.level_mean(k), g.level_mean(k));
    }
}
