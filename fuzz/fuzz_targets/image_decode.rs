//! Image decoding under texel's limits: any bytes either fail with an error or yield a texture
//! within the limits whose every texel is finite.
#![no_main]

use libfuzzer_sys::fuzz_target;
use texel_texture::{ColorSpace, Limits, Texture};

fuzz_target!(|data: &[u8]| {
    let limits = Limits {
        max_dimension: 2048,
        max_bytes: 64 << 20,
    };
    if let Ok(tex) = Texture::decode(data, ColorSpace::Srgb, &limits) {
        assert!(tex.width() <= 2048 && tex.height() <= 2048);
        assert!(tex.pyramid_bytes() <= limits.max_bytes);
        let last = tex.levels().len() - 1;
        for level in [0, last] {
            let l = tex.levels()[level];
            for (i, j) in [(0, 0), (l.width - 1, l.height - 1)] {
                let c = tex.texel(level, i, j).expect("in range");
                assert!(c.iter().all(|v| v.is_finite()), "{c:?}");
            }
        }
    }
});
