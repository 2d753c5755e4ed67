//! What a material reads: a texture through a sampler ([`TextureInput`]), one channel of one
//! ([`ChannelInput`]), and the slope moments LEAN and the projected-roughness methods filter
//! ([`MomentMap`]), with the reads that count texels for the statistics.

use texel_texture::{Footprint, Sampler, Texture};

/// A texture read through a sampler (a material's map).
#[derive(Clone, Copy, Debug)]
pub struct TextureInput<'a> {
    /// The texture.
    pub texture: &'a Texture,
    /// How it is filtered (normally the same filter as the draw's colour texture).
    pub sampler: &'a Sampler,
}

/// One channel of a texture read through a sampler (`0` red ... `3` alpha), multiplying a factor.
#[derive(Clone, Copy, Debug)]
pub struct ChannelInput<'a> {
    /// The texture and its sampler.
    pub input: TextureInput<'a>,
    /// The channel read, `0..=3`.
    pub channel: usize,
}

/// A slope moment map ([`crate::material::lean_map`], [`crate::material::height_moments`]): the first and second moments of a
/// normal or height map's slopes `m`, in two float textures with their own pyramids, read through
/// the map's sampler. Every filter is linear in its texels, so averaged over a footprint they
/// give the mean slope and the slopes' covariance under it (Olano & Baker 2010).
#[derive(Debug)]
pub struct MomentMap {
    /// `[m_x, m_y, m_x^2, m_y^2]`.
    pub moments: Texture,
    /// `[m_x m_y, 0, 0, 0]`: the cross moment, which orients the covariance.
    pub cross: Texture,
}

impl MomentMap {
    /// The moment map of level-0 slopes `slope(i, j)` over a `w x h` map.
    ///
    /// # Errors
    /// The size errors of `Texture::from_fn` for a float texture of that size.
    pub fn from_slopes(
        w: u32,
        h: u32,
        limits: &texel_texture::Limits,
        slope: impl Fn(u32, u32) -> glam::Vec2,
    ) -> Result<MomentMap, texel_texture::TextureError> {
        let format = texel_texture::Format::Rgba32Float;
        let moments = Texture::from_fn(w, h, format, limits, |i, j| {
            let b = slope(i, j);
            [b.x, b.y, b.x * b.x, b.y * b.y]
        })?;
        let cross = Texture::from_fn(w, h, format, limits, |i, j| {
            let b = slope(i, j);
            [b.x * b.y, 0.0, 0.0, 0.0]
        })?;
        Ok(MomentMap { moments, cross })
    }

    /// Bytes the texels of both pyramids occupy.
    pub fn pyramid_bytes(&self) -> u64 {
        self.moments.pyramid_bytes() + self.cross.pyramid_bytes()
    }

    /// The filtered moments `[m_x, m_y, m_x^2, m_y^2, m_x m_y]` at `fp` through `sampler`, adding
    /// the texels read to `texels` when `count`.
    pub fn read(
        &self,
        sampler: &Sampler,
        fp: &Footprint,
        count: bool,
        texels: &mut u32,
    ) -> [f32; 5] {
        let at =
            |texture, texels: &mut u32| read(&TextureInput { texture, sampler }, fp, count, texels);
        let e = at(&self.moments, texels);
        let c = at(&self.cross, texels);
        [e[0], e[1], e[2], e[3], c[0]]
    }
}

/// Read `input` at `fp`, adding the texels read to `texels` when `count`.
pub fn read(input: &TextureInput, fp: &Footprint, count: bool, texels: &mut u32) -> [f32; 4] {
    if count {
        let (t, n) = input.sampler.sample_counted(input.texture, fp);
        *texels += n;
        t
    } else {
        input.sampler.sample(input.texture, fp)
    }
}

/// One channel of `input` at `fp`, adding the texels read to `texels` when `count`.
pub fn read_channel(input: &ChannelInput, fp: &Footprint, count: bool, texels: &mut u32) -> f32 {
    read(&input.input, fp, count, texels)[input.channel]
}
