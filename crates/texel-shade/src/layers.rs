//! Layered materials: up to [`MAX_LAYERS`] layers, each with its own base colour, roughness,
//! normal map and height, blended by a mask texture, linearly or by height.
//!
//! **Weights.** The mask's channel `k` (red, green, blue, alpha) is layer `k`'s weight `m_k`, as
//! terrain "splat maps" store them; the weights are divided by their sum (layer 0 takes all where
//! the sum is 0). A single layer needs no mask and has weight 1.
//!
//! - [`LayerBlend::Linear`]: `w_k = m_k / sum m`.
//! - [`LayerBlend::Height`] (Mishkinis 2013, "Advanced Terrain Texture Splatting"): with each
//!   layer's height `h_k` in `[0, 1]`, `t = max_k (h_k + m_k) - depth` and
//!   `w_k = max(h_k + m_k - t, 0) / sum`: where layers meet, the higher one shows through first
//!   (sand fills the gaps between stones), over a transition `depth` wide.
//!
//! **Filter then blend** ([`Layers::sample`], what a shader does): every map is filtered over
//! the pixel's footprint by the draw's filter, then the filtered values are blended by the
//! weights of the filtered mask and heights. Base colour, roughness and height are blended
//! linearly; normals are blended as the mean of the layers' filtered (unnormalised) tangent-space
//! normals, `sum w_k n_k` (a layer without a normal map contributes `(0, 0, 1)`), so Toksvig sees
//! the spread between layers as well as within them; LEAN's moments are blended likewise, which is
//! exact for a mixture (`E[b] = sum w_k E_k[b]`, `E[b^2] = sum w_k E_k[b^2]`). Because the weights
//! multiply the maps, `filter(w c) != filter(w) filter(c)`: where the mask or the heights vary
//! under a pixel, filter-then-blend differs from blending each sub-sample (what the reference
//! does). **Blend then filter** bakes the blend at level 0 into ordinary textures first (texel's
//! `prepare`), then filters those.

use glam::{Vec3, Vec4};
use texel_texture::{Footprint, Format, Sampler};

use crate::inputs::{read, read_channel, ChannelInput, MomentMap, TextureInput};

/// The most layers a material has (one per mask channel).
pub const MAX_LAYERS: usize = 4;

/// The transition width of [`LayerBlend::Height`] that Mishkinis (2013) uses.
pub const DEFAULT_BLEND_DEPTH: f32 = 0.2;

/// How far an 8-bit normal map's decoded vector may fall short of unit length by quantisation alone
/// (each of three components off by up to 1/255): Toksvig counts lengths within it as 1.
const UNORM8_NORMAL_SLACK: f32 = 0.006_8;

/// One layer of a [`Layers`] material. Inputs are read through their own samplers (normally the
/// draw's filter).
#[derive(Clone, Copy, Debug)]
pub struct Layer<'a> {
    /// Linear RGBA factor multiplying `base_map` (or the colour, without one).
    pub base_color: Vec4,
    /// Base colour texture (linear RGBA after decoding).
    pub base_map: Option<TextureInput<'a>>,
    /// Perceptual roughness factor in `[0, 1]`, multiplying `roughness_map`.
    pub roughness: f32,
    /// Roughness from a texture channel.
    pub roughness_map: Option<ChannelInput<'a>>,
    /// Tangent-space normal map (glTF convention, as [`crate::material::Material::normal_map`]).
    pub normal_map: Option<TextureInput<'a>>,
    /// Scales the normal map's x and y.
    pub normal_scale: f32,
    /// The LEAN moment map of `normal_map` ([`crate::material::lean_map`]), read through the
    /// normal map's sampler; without it LEAN falls back to Toksvig's rule for this material.
    pub lean: Option<&'a MomentMap>,
    /// Height in `[0, 1]` where there is no `height_map` (and the factor multiplying it where
    /// there is one).
    pub height: f32,
    /// Height from a texture channel, `[0, 1]`.
    pub height_map: Option<ChannelInput<'a>>,
}

impl Default for Layer<'_> {
    /// A white layer of roughness 0.5 at height 0.5, without maps.
    fn default() -> Self {
        Layer {
            base_color: Vec4::ONE,
            base_map: None,
            roughness: 0.5,
            roughness_map: None,
            normal_map: None,
            normal_scale: 1.0,
            lean: None,
            height: 0.5,
            height_map: None,
        }
    }
}

/// How the layers' weights are found (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LayerBlend {
    /// The mask's weights.
    Linear,
    /// The mask's weights sharpened by the layers' heights, over a transition `depth` wide
    /// (`> 0`, in height units).
    Height {
        /// Transition width.
        depth: f32,
    },
}

/// A layered material's layers and mask (module docs).
#[derive(Clone, Copy, Debug)]
pub struct Layers<'a> {
    /// The mask (linear; channel `k` weighs layer `k`); may be `None` for a single layer.
    pub mask: Option<TextureInput<'a>>,
    /// The layers, `1..=MAX_LAYERS` of them.
    pub layers: [Layer<'a>; MAX_LAYERS],
    /// How many of `layers` are used.
    pub count: usize,
    /// How they are blended.
    pub blend: LayerBlend,
    /// Whether any layer gives a height (a map or a number): only then does the blended height
    /// shape the surface (bump, parallax, tessellation).
    pub heights: bool,
}

/// The blended tangent-space normal of the layers at a fragment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapNormal {
    /// The mean of the decoded normals before scaling (`2 rgb - 1`, blended): its length is what
    /// Toksvig reads.
    pub raw: Vec3,
    /// The mean normal after each layer's `normal_scale`.
    pub mean: Vec3,
    /// LEAN's moments `[b_x, b_y, b_x^2, b_y^2, b_x b_y]` after scaling, where every
    /// normal-mapped layer has its moment map and they were asked for.
    pub moments: Option<[f32; 5]>,
    /// How far `raw` may fall short of unit length by quantisation (`UNORM8_NORMAL_SLACK`, 0.0068, if
    /// any map is 8-bit, else 0).
    pub slack: f32,
}

/// What [`Layers::sample`] reads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Needs {
    /// Base colour and roughness.
    pub color: bool,
    /// The blended normal.
    pub normal: bool,
    /// LEAN's moments with the normal.
    pub moments: bool,
}

/// The layers blended at one fragment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayerSample {
    /// Blended base colour (linear RGBA); white where not asked for.
    pub base: Vec4,
    /// Blended perceptual roughness; 1 where not asked for.
    pub roughness: f32,
    /// Blended normal where asked for and some layer has a normal map.
    pub normal: Option<MapNormal>,
    /// The layers' weights (summing to 1).
    pub weights: [f32; MAX_LAYERS],
}

impl<'a> Layers<'a> {
    /// Whether the count, factors and channels are in range and the blend depth is positive.
    pub fn is_valid(&self) -> bool {
        let channel_ok = |c: &Option<ChannelInput>| c.is_none_or(|c| c.channel < 4);
        let depth_ok = match self.blend {
            LayerBlend::Linear => true,
            LayerBlend::Height { depth } => depth.is_finite() && depth > 0.0,
        };
        (1..=MAX_LAYERS).contains(&self.count)
            && (self.count == 1 || self.mask.is_some())
            && depth_ok
            && self.used().iter().all(|l| {
                l.base_color.is_finite()
                    && (0.0..=1.0).contains(&l.roughness)
                    && (0.0..=1.0).contains(&l.height)
                    && l.normal_scale.is_finite()
                    && channel_ok(&l.roughness_map)
                    && channel_ok(&l.height_map)
            })
    }

    /// The layers in use.
    pub fn used(&self) -> &[Layer<'a>] {
        &self.layers[..self.count.min(MAX_LAYERS)]
    }

    /// Whether some layer has a normal map (the layers then give the normal).
    pub fn has_normals(&self) -> bool {
        self.used().iter().any(|l| l.normal_map.is_some())
    }

    /// The largest width and height of the layers' height maps (bump mapping's fallback step;
    /// `(1, 1)` without one).
    pub fn height_size(&self) -> (u32, u32) {
        self.used()
            .iter()
            .filter_map(|l| l.height_map.map(|h| h.input.texture))
            .chain(self.mask.map(|m| m.texture))
            .fold((1, 1), |(w, h), t| (w.max(t.width()), h.max(t.height())))
    }

    /// The same layers with every input read through `sampler` instead (the reference's level-0
    /// sampler).
    pub fn with_sampler<'b>(&self, sampler: &'b Sampler) -> Layers<'b>
    where
        'a: 'b,
    {
        let input = |t: TextureInput<'a>| TextureInput {
            texture: t.texture,
            sampler,
        };
        let channel = |c: ChannelInput<'a>| ChannelInput {
            input: input(c.input),
            channel: c.channel,
        };
        let layer = |l: Layer<'a>| Layer {
            base_map: l.base_map.map(input),
            roughness_map: l.roughness_map.map(channel),
            normal_map: l.normal_map.map(input),
            height_map: l.height_map.map(channel),
            ..l
        };
        Layers {
            mask: self.mask.map(input),
            layers: self.layers.map(layer),
            count: self.count,
            blend: self.blend,
            heights: self.heights,
        }
    }

    /// The layers' weights at `fp` (module docs), and their heights where `heights` asks for
    /// them or the blend needs them (0 where not read, and for layers the mask leaves out).
    fn weights(
        &self,
        fp: &Footprint,
        heights: bool,
        count: bool,
        texels: &mut u32,
    ) -> ([f32; MAX_LAYERS], [f32; MAX_LAYERS]) {
        let n = self.count.clamp(1, MAX_LAYERS);
        let mut m = [0.0f32; MAX_LAYERS];
        match (&self.mask, n) {
            (Some(mask), 2..) => {
                let t = read(mask, fp, count, texels);
                for k in 0..n {
                    m[k] = t[k].max(0.0);
                }
            }
            _ => m[0] = 1.0,
        }
        normalise(&mut m);
        let mut h = [0.0f32; MAX_LAYERS];
        let by_height = matches!(self.blend, LayerBlend::Height { .. });
        if heights || by_height {
            // A layer the mask leaves out has no weight under either blend: no read.
            for k in (0..n).filter(|&k| m[k] > 0.0) {
                let l = &self.layers[k];
                h[k] = l.height_map.map_or(l.height, |map| {
                    l.height * read_channel(&map, fp, count, texels)
                });
            }
        }
        if let LayerBlend::Height { depth } = self.blend {
            let top = (0..n)
                .filter(|&k| m[k] > 0.0)
                .map(|k| h[k] + m[k])
                .fold(f32::NEG_INFINITY, f32::max)
                - depth;
            for k in 0..n {
                m[k] = if m[k] > 0.0 {
                    (h[k] + m[k] - top).max(0.0)
                } else {
                    0.0
                };
            }
            normalise(&mut m);
        }
        (m, h)
    }

    /// The blended height at `fp`, `[0, 1]`.
    pub fn height(&self, fp: &Footprint, count: bool, texels: &mut u32) -> f32 {
        let (w, h) = self.weights(fp, true, count, texels);
        w.iter().zip(&h).map(|(w, h)| w * h).sum()
    }

    /// Filter then blend: every map the layers have (of those `needs` asks for) read at `fp`,
    /// blended (module docs); adds the texels read to `texels` when `count`.
    pub fn sample(
        &self,
        fp: &Footprint,
        needs: Needs,
        count: bool,
        texels: &mut u32,
    ) -> LayerSample {
        let (w, _) = self.weights(fp, false, count, texels);
        let mut out = LayerSample {
            base: if needs.color { Vec4::ZERO } else { Vec4::ONE },
            roughness: if needs.color { 0.0 } else { 1.0 },
            normal: None,
            weights: w,
        };
        let normals = needs.normal && self.has_normals();
        let mut normal = MapNormal {
            raw: Vec3::ZERO,
            mean: Vec3::ZERO,
            moments: needs.moments.then_some([0.0; 5]),
            slack: 0.0,
        };
        for (l, &wk) in self.used().iter().zip(&w) {
            if wk == 0.0 {
                continue;
            }
            if needs.color {
                let c = l
                    .base_map
                    .map_or(Vec4::ONE, |t| Vec4::from(read(&t, fp, count, texels)));
                out.base += wk * c * l.base_color;
                let r = l
                    .roughness_map
                    .map_or(1.0, |c| read_channel(&c, fp, count, texels));
                out.roughness += wk * l.roughness * r;
            }
            if !normals {
                continue;
            }
            let Some(map) = &l.normal_map else {
                normal.raw += wk * Vec3::Z;
                normal.mean += wk * Vec3::Z;
                continue;
            };
            let lean = l.lean.filter(|_| normal.moments.is_some());
            let n = read_normal(map, l.normal_scale, lean, fp, count, texels);
            normal.raw += wk * n.raw;
            normal.mean += wk * n.mean;
            normal.slack = normal.slack.max(n.slack);
            normal.moments = normal
                .moments
                .zip(n.moments)
                .map(|(acc, e)| std::array::from_fn(|c| acc[c] + wk * e[c]));
        }
        if normals {
            out.normal = Some(normal);
        }
        out
    }
}

/// One normal map's filtered tangent-space normal at `fp` with its x and y scaled by `scale`, and
/// LEAN's moments read from `lean` (scaled likewise: `b` by `scale`, `b^2` by its square) where it
/// is given.
pub fn read_normal(
    map: &TextureInput,
    scale: f32,
    lean: Option<&MomentMap>,
    fp: &Footprint,
    count: bool,
    texels: &mut u32,
) -> MapNormal {
    let t = read(map, fp, count, texels);
    let raw = Vec3::new(t[0], t[1], t[2]) * 2.0 - Vec3::ONE;
    let moments = lean.map(|lean| {
        let e = lean.read(map.sampler, fp, count, texels);
        let s2 = scale * scale;
        [e[0] * scale, e[1] * scale, e[2] * s2, e[3] * s2, e[4] * s2]
    });
    MapNormal {
        raw,
        mean: raw * Vec3::new(scale, scale, 1.0),
        moments,
        slack: if map.texture.source_format() == Format::Rgba32Float {
            0.0
        } else {
            UNORM8_NORMAL_SLACK
        },
    }
}

/// Divide by the sum; all weight to layer 0 where the sum is not positive.
fn normalise(m: &mut [f32; MAX_LAYERS]) {
    let sum: f32 = m.iter().sum();
    if sum > 0.0 && sum.is_finite() {
        for x in m.iter_mut() {
            *x /= sum;
        }
    } else {
        *m = [1.0, 0.0, 0.0, 0.0];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use texel_texture::{ColorSpace, Limits, SamplerDescriptor, Texture};

    fn solid(rgba: [f32; 4]) -> Texture {
        Texture::from_fn(4, 4, Format::Rgba32Float, &Limits::default(), |_, _| rgba).unwrap()
    }

    fn point() -> Footprint {
        Footprint {
            u: 0.3,
            v: 0.6,
            dudx: 0.0,
            dudy: 0.0,
            dvdx: 0.0,
            dvdy: 0.0,
        }
    }

    #[test]
    fn linear_weights_are_the_normalised_mask() {
        let s = Sampler::new(SamplerDescriptor::default()).unwrap();
        let mask = solid([0.2, 0.6, 0.0, 0.0]);
        let (red, green) = (solid([1.0, 0.0, 0.0, 1.0]), solid([0.0, 1.0, 0.0, 1.0]));
        fn layer<'a>(t: &'a Texture, s: &'a Sampler, r: f32) -> Layer<'a> {
            Layer {
                base_map: Some(TextureInput {
                    texture: t,
                    sampler: s,
                }),
                roughness: r,
                ..Layer::default()
            }
        }
        let layers = Layers {
            mask: Some(TextureInput {
                texture: &mask,
                sampler: &s,
            }),
            layers: [
                layer(&red, &s, 0.2),
                layer(&green, &s, 0.6),
                Layer::default(),
                Layer::default(),
            ],
            count: 2,
            blend: LayerBlend::Linear,
            heights: false,
        };
        assert!(layers.is_valid());
        let needs = Needs {
            color: true,
            ..Needs::default()
        };
        let mut texels = 0;
        let got = layers.sample(&point(), needs, true, &mut texels);
        assert_eq!(got.weights, [0.25, 0.75, 0.0, 0.0]);
        assert!((got.base - Vec4::new(0.25, 0.75, 0.0, 1.0)).length() < 1e-6);
        assert!((got.roughness - (0.25 * 0.2 + 0.75 * 0.6)).abs() < 1e-6);
        // Mask and two colours, one texel each (nearest, level 0 at a point).
        assert_eq!(texels, 3);
        // An empty mask gives layer 0 everything.
        let empty = solid([0.0; 4]);
        let mut l0 = layers;
        l0.mask = Some(TextureInput {
            texture: &empty,
            sampler: &s,
        });
        let got = l0.sample(&point(), needs, false, &mut texels);
        assert_eq!(got.weights, [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(got.base, Vec4::new(1.0, 0.0, 0.0, 1.0));
    }

    /// Mishkinis's rule by hand: mask (0.5, 0.5), heights 0.9 and 0.3, depth 0.2: `t = 1.4 - 0.2`,
    /// so layer 0 takes `0.2 / 0.2` and layer 1 `max(0.8 - 1.2, 0) = 0`. With closer heights
    /// (0.9, 0.8) both show: `t = 1.2`, weights `0.2 : 0.1`.
    #[test]
    fn height_blending_lets_the_higher_layer_through() {
        let s = Sampler::new(SamplerDescriptor::default()).unwrap();
        let mask = solid([0.5, 0.5, 0.0, 0.0]);
        let heights = solid([0.9, 0.8, 0.0, 1.0]);
        let ch = |c| ChannelInput {
            input: TextureInput {
                texture: &heights,
                sampler: &s,
            },
            channel: c,
        };
        let mut layers = Layers {
            mask: Some(TextureInput {
                texture: &mask,
                sampler: &s,
            }),
            layers: [
                Layer {
                    height: 0.9,
                    ..Layer::default()
                },
                Layer {
                    height: 0.3,
                    ..Layer::default()
                },
                Layer::default(),
                Layer::default(),
            ],
            count: 2,
            blend: LayerBlend::Height { depth: 0.2 },
            heights: true,
        };
        let mut texels = 0;
        let got = layers.sample(&point(), Needs::default(), false, &mut texels);
        assert!((got.weights[0] - 1.0).abs() < 1e-6 && got.weights[1] == 0.0);
        assert!((layers.height(&point(), false, &mut texels) - 0.9).abs() < 1e-6);
        layers.layers[0] = Layer {
            height: 1.0,
            height_map: Some(ch(0)),
            ..Layer::default()
        };
        layers.layers[1] = Layer {
            height: 1.0,
            height_map: Some(ch(1)),
            ..Layer::default()
        };
        let got = layers.sample(&point(), Needs::default(), false, &mut texels);
        assert!(
            (got.weights[0] - 2.0 / 3.0).abs() < 1e-5,
            "{:?}",
            got.weights
        );
        assert!((got.weights[1] - 1.0 / 3.0).abs() < 1e-5);
        let want = (2.0 * 0.9 + 0.8) / 3.0;
        assert!((layers.height(&point(), false, &mut texels) - want).abs() < 1e-5);
    }

    /// Blended normals are the weighted mean; LEAN's moments of a mixture are the weighted
    /// moments (so a tilted layer and a flat one give the variance between them).
    #[test]
    fn normals_and_moments_blend_as_a_mixture() {
        let s = Sampler::new(SamplerDescriptor::default()).unwrap();
        let mask = solid([0.5, 0.5, 0.0, 0.0]);
        let n = Vec3::new(0.6, 0.0, 0.8);
        let code = |c: f32| ((c + 1.0) / 2.0 * 255.0).round() as u8;
        let tilted = Texture::from_rgba8(
            2,
            2,
            vec![[code(n.x), code(n.y), code(n.z), 255]; 4],
            ColorSpace::Linear,
            &Limits::default(),
        )
        .unwrap();
        let lean = crate::material::lean_map(&tilted, &Limits::default()).unwrap();
        let layers = Layers {
            mask: Some(TextureInput {
                texture: &mask,
                sampler: &s,
            }),
            layers: [
                Layer {
                    normal_map: Some(TextureInput {
                        texture: &tilted,
                        sampler: &s,
                    }),
                    lean: Some(&lean),
                    ..Layer::default()
                },
                Layer::default(),
                Layer::default(),
                Layer::default(),
            ],
            count: 2,
            blend: LayerBlend::Linear,
            heights: false,
        };
        let needs = Needs {
            normal: true,
            moments: true,
            ..Needs::default()
        };
        let got = layers.sample(&point(), needs, false, &mut 0);
        let normal = got.normal.unwrap();
        let t = tilted.texel(0, 0, 0).unwrap();
        let decoded = Vec3::new(t[0], t[1], t[2]) * 2.0 - Vec3::ONE;
        assert!((normal.raw - 0.5 * (decoded + Vec3::Z)).length() < 1e-6);
        let b = decoded.x / decoded.z;
        let m = normal.moments.unwrap();
        assert!((m[0] - 0.5 * b).abs() < 1e-5 && (m[2] - 0.5 * b * b).abs() < 1e-5);
        // Variance of a 50:50 mixture of slopes b and 0: b^2 / 4.
        assert!((m[2] - m[0] * m[0] - b * b / 4.0).abs() < 1e-5);
        assert_eq!(normal.slack, UNORM8_NORMAL_SLACK);
    }
}
