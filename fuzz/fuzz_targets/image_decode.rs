//! Image decoding under texel's limits: any bytes either fail with an error or yield a texture
//! within the limits whose every texel is finite. A panic inside a third-party decoder that
//! `texel_texture::input::guarded` turns into an error is not a crash; any other panic is.
#![no_main]

use libfuzzer_sys::fuzz_target;
use texel_texture::{ColorSpace, Limits, Texture};

fuzz_target!(
    init: {
        // libFuzzer's hook aborts on every panic; pass on only those texel does not catch.
        let abort_hook = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !texel_texture::input::in_guarded_decode() {
                abort_hook(info);
            }
        }));
    },
    |data: &[u8]| {
    let limits = Limits {
        max_dimension: 512,
        max_bytes: 16 << 20,
    };
    if let Ok(tex) = Texture::decode(data, ColorSpace::Srgb, &limits) {
        assert!(tex.width() <= 512 && tex.height() <= 512);
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
