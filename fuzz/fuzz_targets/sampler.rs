//! The sampler: an arbitrary descriptor, texture size, texels and footprint (any floats, NaN and
//! infinities included) either make `Sampler::new` refuse the descriptor or give a finite result;
//! every filter but the cubic ones stays within the range of the texels and the border colour, and
//! the cubic ones (whose negative lobes overshoot) within 5.5 times their largest magnitude
//! (`texel_texture::base::filter::MAX_CUBIC_PARAMETER`'s bound).
#![no_main]

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use texel_texture::{
    AddressMode, BorderColor, Cubic, FilterMode, Footprint, Format, Limits, MipmapFilterMode,
    Sampler, SamplerDescriptor, Texture,
};

#[derive(Arbitrary, Debug)]
struct Input {
    width: u8,
    height: u8,
    float: bool,
    seed: u32,
    mode_u: u8,
    mode_v: u8,
    mag: u8,
    min: u8,
    mip: u8,
    cubic: (f32, f32),
    lod_min: f32,
    lod_max: f32,
    bias: f32,
    anisotropy: u16,
    border: u8,
    footprint: [f32; 6],
}

fn address(k: u8) -> AddressMode {
    [
        AddressMode::Repeat,
        AddressMode::MirrorRepeat,
        AddressMode::ClampToEdge,
        AddressMode::ClampToBorder,
        AddressMode::MirrorClampToEdge,
    ][usize::from(k % 5)]
}

fn filter(k: u8, cubic: (f32, f32)) -> FilterMode {
    match k % 6 {
        0 => FilterMode::Nearest,
        1 => FilterMode::Linear,
        2 => FilterMode::Cubic(Cubic {
            b: cubic.0,
            c: cubic.1,
        }),
        3 => FilterMode::Ewa,
        4 => FilterMode::Ripmap,
        _ => FilterMode::SummedArea,
    }
}

fuzz_target!(|input: Input| {
    let (w, h) = (
        u32::from(input.width % 48) + 1,
        u32::from(input.height % 48) + 1,
    );
    // Texels from a small hash of the seed: values in [0, 1].
    let texel = |i: u32, j: u32| {
        let mut x = input.seed ^ i.wrapping_mul(0x9E37_79B9) ^ j.wrapping_mul(0x85EB_CA6B);
        x ^= x >> 15;
        x = x.wrapping_mul(0x2C1B_3C6D);
        x ^= x >> 12;
        let f = |s: u32| ((x >> s) & 0xFF) as f32 / 255.0;
        [f(0), f(8), f(16), f(24)]
    };
    let format = if input.float {
        Format::Rgba32Float
    } else {
        Format::Rgba8Unorm
    };
    let tex = Texture::from_fn(w, h, format, &Limits::default(), texel).expect("valid size");
    let desc = SamplerDescriptor {
        address_mode_u: address(input.mode_u),
        address_mode_v: address(input.mode_v),
        mag_filter: filter(input.mag, input.cubic),
        min_filter: filter(input.min, input.cubic),
        mipmap_filter: [
            MipmapFilterMode::None,
            MipmapFilterMode::Nearest,
            MipmapFilterMode::Linear,
        ][usize::from(input.mip % 3)],
        lod_min_clamp: input.lod_min,
        lod_max_clamp: input.lod_max,
        lod_bias: input.bias,
        anisotropy_clamp: input.anisotropy,
        border_color: [
            BorderColor::TransparentBlack,
            BorderColor::OpaqueBlack,
            BorderColor::OpaqueWhite,
        ][usize::from(input.border % 3)],
    };
    let Ok(sampler) = Sampler::new(desc) else {
        return;
    };
    let [u, v, dudx, dudy, dvdx, dvdy] = input.footprint;
    let fp = Footprint {
        u,
        v,
        dudx,
        dudy,
        dvdx,
        dvdy,
    };
    if tex.build_structures(&sampler).is_err() {
        return;
    }
    let c = sampler.sample(&tex, &fp);
    assert!(c.iter().all(|x| x.is_finite()), "{c:?} for {input:?}");
    // Every level of the pyramid is an average of level 0, so its texels lie in level 0's range.
    let mut lo = [f32::INFINITY; 4];
    let mut hi = [f32::NEG_INFINITY; 4];
    for j in 0..h {
        for i in 0..w {
            let t = tex.texel(0, i, j).unwrap();
            for k in 0..4 {
                lo[k] = lo[k].min(t[k]);
                hi[k] = hi[k].max(t[k]);
            }
        }
    }
    let border = desc.border_color.rgba();
    let cubic = matches!(desc.mag_filter, FilterMode::Cubic(_))
        || matches!(desc.min_filter, FilterMode::Cubic(_));
    if cubic {
        for k in 0..4 {
            let m = lo[k].abs().max(hi[k].abs()).max(border[k].abs());
            assert!(
                c[k].abs() <= 5.5 * m + 1e-4,
                "channel {k}: {} beyond 5.5 x {m} for {input:?}",
                c[k]
            );
        }
    } else {
        for k in 0..4 {
            // 8-bit levels are re-quantised, so allow one code of slack.
            let eps = 1.0 / 255.0 + 1e-4;
            let (a, b) = (lo[k].min(border[k]) - eps, hi[k].max(border[k]) + eps);
            assert!(
                c[k] >= a && c[k] <= b,
                "channel {k}: {} outside [{a}, {b}] for {input:?}",
                c[k]
            );
        }
    }
});
