//! Blend then filter: a layered material ([`texel_raster::layers`]) blended texel by texel at
//! level 0 into one set of ordinary maps, which the draw's filter then filters like any texture
//! (`layer_order = "blend-then-filter"`). The same baked heights displace tessellated layered
//! geometry (and the reference's) in either order.
//!
//! The maps are `Rgba32Float` (no requantisation) at the largest width and height of the
//! material's textures. Texel `(i, j)` is the layers blended at its centre
//! `((i + 0.5) / w, (j + 0.5) / h)`, every input read bilinearly at level 0 with the mesh's
//! address modes, as the reference reads them; its normal is the blended tangent-space normal,
//! normalised there (so the baked map's mip levels shorten it where the layers' normals
//! disagree, as Toksvig expects) and coded `(n + 1) / 2` like an 8-bit normal map.

use glam::Vec3;
use texel_raster::layers::{Layers, Needs};
use texel_raster::reference::level0_descriptor;
use texel_texture::{
    AddressMode, Footprint, Format, Limits, Sampler, SamplerDescriptor, Texture, TextureError,
};

/// A layered material's blend, baked.
#[derive(Debug)]
pub struct Composite {
    /// Blended base colour, linear RGBA.
    pub base: Texture,
    /// Blended perceptual roughness in red.
    pub roughness: Texture,
    /// Blended tangent-space normal, coded `(n + 1) / 2`, where some layer has a normal map.
    pub normal: Option<Texture>,
    /// Blended height in red, where some layer gives a height.
    pub height: Option<Texture>,
}

impl Composite {
    /// Bytes of every map with its pyramid.
    pub fn bytes(&self) -> u64 {
        [Some(&self.base), Some(&self.roughness)]
            .into_iter()
            .chain([self.normal.as_ref(), self.height.as_ref()])
            .flatten()
            .map(Texture::pyramid_bytes)
            .sum()
    }
}

/// A sampler reading level 0 bilinearly with address modes `modes`, as the reference reads
/// ([`texel_raster::reference::level0_descriptor`]).
pub fn level0_sampler(modes: (AddressMode, AddressMode)) -> Result<Sampler, TextureError> {
    Sampler::new(level0_descriptor(&SamplerDescriptor {
        address_mode_u: modes.0,
        address_mode_v: modes.1,
        ..SamplerDescriptor::default()
    }))
}

/// The size the layers are baked at: the largest width and height of the textures they read.
pub fn composite_size(layers: &Layers) -> (u32, u32) {
    let used = layers.used().iter().flat_map(|l| {
        [
            l.base_map.map(|t| t.texture),
            l.roughness_map.map(|c| c.input.texture),
            l.normal_map.map(|t| t.texture),
            l.height_map.map(|c| c.input.texture),
        ]
    });
    used.chain([layers.mask.map(|m| m.texture)])
        .flatten()
        .fold((1, 1), |(w, h), t| (w.max(t.width()), h.max(t.height())))
}

/// Bake `layers` (whose inputs may use any sampler: they are read at level 0 through
/// `level0`) into a [`Composite`] of [`composite_size`].
///
/// # Errors
/// The size errors of `Texture::from_fn` under `limits` (each map is checked before it is made).
pub fn bake(layers: &Layers, level0: &Sampler, limits: &Limits) -> Result<Composite, TextureError> {
    let layers = layers.with_sampler(level0);
    let (w, h) = composite_size(&layers);
    let centre = |i: u32, j: u32| Footprint {
        u: (i as f32 + 0.5) / w as f32,
        v: (j as f32 + 0.5) / h as f32,
        dudx: 0.0,
        dudy: 0.0,
        dvdx: 0.0,
        dvdy: 0.0,
    };
    let at = |i: u32, j: u32, needs: Needs| layers.sample(&centre(i, j), needs, false, &mut 0);
    let color = Needs {
        color: true,
        ..Needs::default()
    };
    let map =
        |f: &dyn Fn(u32, u32) -> [f32; 4]| Texture::from_fn(w, h, Format::Rgba32Float, limits, f);
    let base = map(&|i, j| at(i, j, color).base.to_array())?;
    let roughness = map(&|i, j| {
        let r = at(i, j, color).roughness;
        [r, r, r, 1.0]
    })?;
    let normal = if layers.has_normals() {
        let normals = Needs {
            normal: true,
            ..Needs::default()
        };
        Some(map(&|i, j| {
            let n = at(i, j, normals)
                .normal
                .map_or(Vec3::Z, |n| n.mean.normalize_or(Vec3::Z));
            let c = (n + Vec3::ONE) * 0.5;
            [c.x, c.y, c.z, 1.0]
        })?)
    } else {
        None
    };
    let height = if layers.heights {
        Some(map(&|i, j| {
            let h = layers.height(&centre(i, j), false, &mut 0);
            [h, h, h, 1.0]
        })?)
    } else {
        None
    };
    Ok(Composite {
        base,
        roughness,
        normal,
        height,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;
    use texel_raster::layers::{Layer, LayerBlend, MAX_LAYERS};
    use texel_raster::{ChannelInput, TextureInput};
    use texel_texture::base::rng::SplitMix64;

    /// A 2-layer mask whose weights sum to 1 texel by texel, and a height map.
    fn maps() -> (Texture, Texture) {
        let limits = Limits::default();
        let mut rng = SplitMix64::new(5);
        let w: Vec<f32> = (0..32 * 32).map(|_| rng.next_f32()).collect();
        let mask = Texture::from_fn(32, 32, Format::Rgba32Float, &limits, |i, j| {
            let a = w[(j * 32 + i) as usize];
            [a, 1.0 - a, 0.0, 0.0]
        })
        .unwrap();
        let heights = Texture::from_fn(32, 32, Format::Rgba32Float, &limits, |i, j| {
            let h = ((i * 7 + j * 13) % 11) as f32 / 10.0;
            [h, 1.0 - h, 0.0, 1.0]
        })
        .unwrap();
        (mask, heights)
    }

    fn layers<'a>(
        mask: &'a Texture,
        heights: &'a Texture,
        sampler: &'a Sampler,
        blend: LayerBlend,
    ) -> Layers<'a> {
        let constant = |c: Vec4, ch: usize| Layer {
            base_color: c,
            height: 1.0,
            height_map: Some(ChannelInput {
                input: TextureInput {
                    texture: heights,
                    sampler,
                },
                channel: ch,
            }),
            ..Layer::default()
        };
        let mut l = [Layer::default(); MAX_LAYERS];
        l[0] = constant(Vec4::new(0.9, 0.2, 0.1, 1.0), 0);
        l[1] = constant(Vec4::new(0.1, 0.3, 0.8, 1.0), 1);
        Layers {
            mask: Some(TextureInput {
                texture: mask,
                sampler,
            }),
            layers: l,
            count: 2,
            blend,
            heights: true,
        }
    }

    /// The largest colour difference between the baked layers filtered and the layers filtered
    /// then blended, over footprints from magnified to strongly minified and anisotropic.
    fn largest_difference(blend: LayerBlend, desc: SamplerDescriptor) -> f32 {
        let (mask, heights) = maps();
        let modes = (AddressMode::Repeat, AddressMode::Repeat);
        let level0 = level0_sampler(modes).unwrap();
        let sampler = Sampler::new(desc).unwrap();
        let ly = layers(&mask, &heights, &sampler, blend);
        let baked = bake(&ly, &level0, &Limits::default()).unwrap();
        let needs = Needs {
            color: true,
            ..Needs::default()
        };
        let mut rng = SplitMix64::new(9);
        let mut worst = 0.0f32;
        for _ in 0..2000 {
            let scale = 2f32.powf(rng.next_f32() * 12.0 - 8.0);
            let fp = Footprint {
                u: rng.next_f32(),
                v: rng.next_f32(),
                dudx: scale * (rng.next_f32() - 0.5),
                dudy: scale * (rng.next_f32() - 0.5) * 0.2,
                dvdx: scale * (rng.next_f32() - 0.5) * 0.2,
                dvdy: scale * (rng.next_f32() - 0.5),
            };
            let a = Vec4::from(sampler.sample(&baked.base, &fp));
            let b = ly.sample(&fp, needs, false, &mut 0).base;
            worst = worst.max((a - b).abs().max_element());
        }
        worst
    }

    /// Filtering is linear and a linear blend of constant layers is linear in the mask, so the
    /// two orders agree to rounding under every filter; blending by height is not linear, and
    /// there they part.
    #[test]
    fn the_orders_agree_exactly_where_the_blend_is_linear() {
        use crate::Filter;
        for filter in [Filter::Trilinear, Filter::Aniso16, Filter::Ewa, Filter::Sat] {
            let d = filter.descriptor(AddressMode::Repeat, AddressMode::Repeat);
            let linear = largest_difference(LayerBlend::Linear, d);
            assert!(linear < 2e-5, "{:?}: {linear}", d.min_filter);
            let height = largest_difference(LayerBlend::Height { depth: 0.2 }, d);
            assert!(height > 0.1, "{:?}: {height}", d.min_filter);
        }
    }
}
