//! The supersampled reference renderer: the ground truth every filter is judged against
//! (docs/guide/conventions.md, "Reference images and quality").
//!
//! Each pixel `(i, j)` gets `nx x ny` stratified jittered samples at
//! `(i + (sx + xi) / nx, j + (sy + eta) / ny)` (`nx = ny = n` for [`render_reference`]; 512 samples
//! are 16 x 32 with [`render_reference_strata`]), `xi, eta` uniform in `[0, 1)` from a per-pixel SplitMix64
//! stream seeded by `(seed, i, j)`. Each sample finds its visible triangle with the rasterizer's own
//! fixed-point edge functions, top-left rule and `f32` less-than depth (the sample position rounded to
//! 1/256 pixel, as the rasterizer snaps), then interpolates `uv` perspective-correctly *at its exact
//! sub-pixel position* from the same homogeneous plane equations, samples the texture bilinearly at
//! level 0 (a sampler with Linear mag/min filters, no mipmapping, and the draw's address modes and
//! border colour), and shades as [`crate::View::Color`] does (vertex colour; under lights the same
//! material model, its maps read bilinearly at level 0 too and the normals used exactly, without
//! specular antialiasing).
//! Samples that hit nothing take the background colour, or the environment's radiance along
//! their own ray, read bilinearly at level 0, where the environment is the background. The pixel is the plain mean (box filter) in
//! linear light.
//!
//! Design, for speed (it is asked for 256 spp at 1280 x 720): triangle setup and binning are the
//! rasterizer's, done once; each tile is processed one pixel row at a time, first resolving
//! visibility for all `64 nx ny` samples of the row (integer edge tests against the row's triangles
//! only, with a per-sample depth and winner buffer), then shading each sample once, so hidden
//! samples are never shaded. Tiles run in parallel; the result is independent of the thread count.
//! Its time for 16 x 16 spp of the ground scene at 1280 x 720 is in docs/benchmarks.md
//! (`examples/frame_table.rs`; `examples/ground.rs` prints it too).
//! The settings' `view`, `derivatives` and `perspective` are ignored (always colour, level 0,
//! perspective-correct); `count_texels` and `capture_footprints` leave their buffers empty; the
//! colour target is always [`crate::ColorTarget::Float`] (the reference's averages are quantised
//! once, by whoever compares against them), and the depth is the nearest sub-sample's. A
//! scissor rectangle limits the pixels rendered, which are the same as without it; the rest keep
//! the background.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use glam::{DVec2, DVec3, Vec4};
use rayon::prelude::*;
use texel_texture::{FilterMode, MipmapFilterMode, Sampler, SamplerDescriptor};

use crate::draw::{DrawCall, UvEvaluation, UvMapping};
use crate::environment::{Environment, ViewRays};
use crate::error::RasterError;
use crate::frame::Frame;
use crate::material::{ChannelInput, Material, SpecularAa, TextureInput};
use crate::point::ShadingPoint;
use crate::settings::{ColorTarget, Perspective, RenderSettings};
use crate::setup::{setup_draws, validate_draws, TriangleSetup, SUBPIXEL};
use crate::shade::{shade, DrawContext, Lighting, Shader};
use crate::tile::{bin, split_rows, tile_counts, TILE};
use texel_texture::base::rng::SplitMix64;

/// The largest samples-per-pixel side (`64 x 64 = 4096` samples per pixel).
pub const MAX_SPP_SIDE: u32 = 64;

/// The default samples-per-pixel side (16 x 16 = 256 samples, conventions.md).
pub const DEFAULT_SPP_SIDE: u32 = 16;

/// `spp` samples as `[n, m]` strata with `n <= m`, as square as `spp` divides (256 -> 16 x 16,
/// 512 -> 16 x 32, 7 -> 1 x 7).
pub fn square_strata(spp: u32) -> [u32; 2] {
    let mut n = (f64::from(spp).sqrt().floor() as u32).max(1);
    while !spp.is_multiple_of(n) {
        n -= 1;
    }
    [n, spp / n]
}

/// Progress callback: `(pixels done, pixels in total)`, called from worker threads after each tile.
pub type Progress<'a> = &'a (dyn Fn(u64, u64) + Sync);

/// Render the reference image of `draws` with `spp_side x spp_side` stratified jittered samples per
/// pixel (see the module docs). Deterministic for a given `seed`, whatever the thread count.
///
/// `progress`, if given, is called with `(pixels done, total pixels)` after each 64x64 tile, from
/// worker threads, in no particular order of tiles (the count is monotonic).
///
/// # Errors
/// As [`crate::render`], plus [`RasterError::InvalidSamplesPerPixel`] for `spp_side` outside
/// `1..=MAX_SPP_SIDE`.
pub fn render_reference(
    settings: &RenderSettings,
    draws: &[DrawCall],
    spp_side: u32,
    seed: u64,
    progress: Option<Progress>,
) -> Result<Frame, RasterError> {
    render_reference_strata(settings, draws, [spp_side, spp_side], seed, progress)
}

/// As [`render_reference`] with `strata[0] x strata[1]` (columns x rows) stratified jittered samples
/// per pixel, e.g. `[16, 32]` for the lectures' 512 samples.
///
/// # Errors
/// As [`render_reference`], for either side outside `1..=MAX_SPP_SIDE`.
pub fn render_reference_strata(
    settings: &RenderSettings,
    draws: &[DrawCall],
    strata: [u32; 2],
    seed: u64,
    progress: Option<Progress>,
) -> Result<Frame, RasterError> {
    with_passes(settings, draws, strata, |pass| {
        pass(seed, None, progress, None).map(|(frame, _)| frame)
    })
}

/// One pass of the reference: every pixel (or, with `Some(active)`, those whose entry of the
/// row-major mask is true; the others keep the background) gets one stratified estimate with the
/// given seed. A stop flag, once set, ends the pass between pixel rows: the pass then also returns
/// which pixels it rendered (row-major), each of them whole.
pub(crate) type Pass<'p> = dyn FnMut(
        u64,
        Option<&[bool]>,
        Option<Progress>,
        Option<&AtomicBool>,
    ) -> Result<(Frame, Option<Vec<bool>>), RasterError>
    + 'p;

/// Validate `settings`, `draws` and `strata`, make the level-0 samplers and materials the
/// reference reads through, and hand `body` a function that renders one pass with them (on the
/// settings' thread pool).
pub(crate) fn with_passes<T: Send>(
    settings: &RenderSettings,
    draws: &[DrawCall],
    strata: [u32; 2],
    body: impl FnOnce(&mut Pass) -> Result<T, RasterError> + Send,
) -> Result<T, RasterError> {
    settings.validate()?;
    for spp_side in strata {
        if !(1..=MAX_SPP_SIDE).contains(&spp_side) {
            return Err(RasterError::InvalidSamplesPerPixel {
                spp_side,
                max: MAX_SPP_SIDE,
            });
        }
    }
    validate_draws(draws)?;
    let samplers = draws
        .iter()
        .map(|d| level0(d.sampler))
        .collect::<Result<Vec<_>, _>>()?;
    let map_samplers = map_samplers(draws)?;
    let materials = reference_materials(draws, &map_samplers);
    crate::with_threads(settings.threads, || {
        // Triangle setup, binning and the draws' contexts serve every pass.
        let (width, height) = (settings.width, settings.height);
        let setups = setup_draws(settings, draws)?;
        // Sub-samples reach the whole pixel: bin by the sample box, so a triangle that ends just
        // short of a tile's first pixel centre, or covers no centre at all, still reaches its
        // samples.
        let bins = bin(
            &setups,
            width,
            height,
            |t| Some(t.sample_bbox),
            |s, _| s as u32,
        );
        let ref_draws: Vec<DrawCall> = draws
            .iter()
            .zip(&samplers)
            .zip(&materials)
            .map(|((d, s), m)| DrawCall {
                sampler: s,
                material: *m,
                // The reference evaluates a sphere mapping at every sample, whichever way the
                // rasterizer does: the ground truth both evaluations approximate.
                uv_mapping: d.uv_mapping.map(|m| UvMapping {
                    evaluation: UvEvaluation::PerPixel,
                    ..m
                }),
                ..*d
            })
            .collect();
        let contexts: Vec<DrawContext> = ref_draws.iter().map(DrawContext::new).collect();
        let shared = Context {
            settings,
            setups: &setups,
            draws: &contexts,
            lighting: Lighting::of(settings, true),
            background: settings
                .environment
                .and_then(|e| Some((e, e.background_rays(width, height)?))),
            strata,
            seed: 0,
            active: None,
        };
        let mut pass = |seed: u64,
                        active: Option<&[bool]>,
                        progress: Option<Progress>,
                        stop: Option<&AtomicBool>| {
            let ctx = Context {
                seed,
                active,
                ..shared.clone()
            };
            Ok(reference_pass(&ctx, &bins, progress, stop))
        };
        body(&mut pass)
    })
}

/// The level-0 samplers of each draw's material maps: roughness, metallic, normal, height,
/// layers (read through the draw's own filter), occlusion; `None` where the draw has no such map.
fn map_samplers(draws: &[DrawCall]) -> Result<Vec<[Option<Sampler>; 6]>, RasterError> {
    draws
        .iter()
        .map(|d| -> Result<[Option<Sampler>; 6], RasterError> {
            let Some(m) = d.material else {
                return Ok([None, None, None, None, None, None]);
            };
            Ok([
                m.roughness_map
                    .map(|c| level0(c.input.sampler))
                    .transpose()?,
                m.metallic_map
                    .map(|c| level0(c.input.sampler))
                    .transpose()?,
                m.normal_map.map(|t| level0(t.sampler)).transpose()?,
                m.height_map.map(|c| level0(c.input.sampler)).transpose()?,
                // Every input of a layered material is read through the draw's own filter.
                m.layers.map(|_| level0(d.sampler)).transpose()?,
                m.occlusion_map
                    .map(|c| level0(c.input.sampler))
                    .transpose()?,
            ])
        })
        .collect()
}

/// Each draw's material as the reference reads it: its maps at level 0 through `samplers`
/// ([`map_samplers`]), and the normals exactly (no specular antialiasing, one shading sample:
/// the sub-samples resolve the variation those approximate).
fn reference_materials<'a>(
    draws: &[DrawCall<'a>],
    samplers: &'a [[Option<Sampler>; 6]],
) -> Vec<Option<Material<'a>>> {
    draws
        .iter()
        .zip(samplers)
        .map(|(d, [r, m, n, h, ly, o])| {
            d.material.map(|mat| Material {
                layers: mat.layers.zip(ly.as_ref()).map(|(l, s)| l.with_sampler(s)),
                roughness_map: channel(mat.roughness_map, r),
                metallic_map: channel(mat.metallic_map, m),
                height_map: channel(mat.height_map, h),
                occlusion_map: channel(mat.occlusion_map, o),
                normal_map: mat
                    .normal_map
                    .zip(n.as_ref())
                    .map(|(t, s)| TextureInput { sampler: s, ..t }),
                specular_aa: SpecularAa::None,
                shading_samples: 1,
                ..mat
            })
        })
        .collect()
}

/// `c` read through sampler `s` instead of its own.
fn channel<'a>(c: Option<ChannelInput<'a>>, s: &'a Option<Sampler>) -> Option<ChannelInput<'a>> {
    c.zip(s.as_ref()).map(|(c, s)| ChannelInput {
        input: TextureInput {
            sampler: s,
            ..c.input
        },
        ..c
    })
}

/// How the reference reads every texture: `desc` made to read level 0 bilinearly (no mipmaps,
/// no anisotropy), keeping its address modes and border colour.
pub fn level0_descriptor(desc: &SamplerDescriptor) -> SamplerDescriptor {
    SamplerDescriptor {
        mag_filter: FilterMode::Linear,
        min_filter: FilterMode::Linear,
        mipmap_filter: MipmapFilterMode::None,
        anisotropy_clamp: 1,
        lod_min_clamp: 0.0,
        lod_max_clamp: 32.0,
        lod_bias: 0.0,
        ..*desc
    }
}

/// `sampler` as the reference reads through it ([`level0_descriptor`]).
fn level0(sampler: &Sampler) -> Result<Sampler, RasterError> {
    Ok(Sampler::new(level0_descriptor(sampler.descriptor()))?)
}

/// What a pass reads: the frame's setup, shared by every pass, and the pass's seed and pixels.
#[derive(Clone)]
struct Context<'a> {
    settings: &'a RenderSettings<'a>,
    setups: &'a [TriangleSetup],
    draws: &'a [DrawContext<'a>],
    lighting: Option<Lighting<'a>>,
    /// The environment and its camera rays, when it is the background.
    background: Option<(Environment<'a>, ViewRays)>,
    strata: [u32; 2],
    seed: u64,
    /// The pixels to render (row-major), or all.
    active: Option<&'a [bool]>,
}

/// One pass of the reference with `ctx`'s seed over its active pixels (the others keep the
/// background). Once `stop` is set, no further pixel row starts; the rows rendered are then
/// returned as a row-major mask (`None`: the whole pass).
fn reference_pass(
    ctx: &Context,
    bins: &[Vec<u32>],
    progress: Option<Progress>,
    stop: Option<&AtomicBool>,
) -> (Frame, Option<Vec<bool>>) {
    let settings = ctx.settings;
    let (width, height) = (settings.width, settings.height);
    let pixels = width as usize * height as usize;
    let mut frame = Frame {
        width,
        height,
        target: ColorTarget::Float,
        color: vec![settings.background; pixels],
        color8: Vec::new(),
        texels_read: Vec::new(),
        depth: vec![f32::INFINITY; pixels],
        footprints: Vec::new(),
        cleared: Default::default(),
    };
    let (tx, _) = tile_counts(width, height);
    let color = split_rows(&mut frame.color, width, height);
    let depth = split_rows(&mut frame.depth, width, height);
    let mut rendered = if stop.is_some() {
        vec![false; pixels]
    } else {
        Vec::new()
    };
    let rendered_rows = split_rows(&mut rendered, width, height);
    let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let done = AtomicU64::new(0);
    let total = pixels as u64;
    color
        .into_par_iter()
        .zip(depth)
        .zip(rendered_rows)
        .zip(bins.par_iter())
        .enumerate()
        .with_max_len(1)
        .for_each(|(k, (((mut color, mut depth), mut marks), bin))| {
            let (x0, y0) = ((k as u32 % tx) * TILE, (k as u32 / tx) * TILE);
            let mut scratch = Scratch::default();
            // The tile's columns inside the scissor (as offsets into its rows).
            let [sx0, sy0, sx1, sy1] = settings.scissor_rect();
            let tw = color.first().map_or(0, |r| r.len() as u32);
            let (c0, c1) = (sx0.clamp(x0, x0 + tw) - x0, sx1.clamp(x0, x0 + tw) - x0);
            for (r, (crow, drow)) in color.iter_mut().zip(depth.iter_mut()).enumerate() {
                if stopped() {
                    break;
                }
                if let Some(row) = marks.get_mut(r) {
                    row.fill(true);
                }
                let j = y0 + r as u32;
                if c0 < c1 && (sy0..sy1).contains(&j) {
                    let (c0, c1) = (c0 as usize, c1 as usize);
                    let (crow, drow) = (&mut crow[c0..c1], &mut drow[c0..c1]);
                    reference_row(ctx, bin, x0 + c0 as u32, j, crow, drow, &mut scratch);
                }
            }
            let tile_pixels = color.iter().map(|r| r.len() as u64).sum::<u64>();
            let now = done.fetch_add(tile_pixels, Ordering::Relaxed) + tile_pixels;
            if let Some(p) = progress {
                p(now, total);
            }
        });
    let whole = rendered.iter().all(|&r| r);
    (frame, (!whole).then_some(rendered))
}

/// Per-thread buffers for one pixel row of a tile.
#[derive(Default)]
struct Scratch {
    /// The row's pixels being rendered, as offsets into the row.
    pixels: Vec<u32>,
    pos: Vec<DVec2>,
    fixed: Vec<[i64; 2]>,
    depth: Vec<f32>,
    winner: Vec<u32>,
}

/// Render the pixels `x0 .. x0 + color.len()` of row `j` (those the context's mask holds):
/// place their stratified samples, find the nearest triangle at each, and shade.
fn reference_row(
    ctx: &Context,
    bin: &[u32],
    x0: u32,
    j: u32,
    color: &mut [[f32; 4]],
    depth: &mut [f32],
    s: &mut Scratch,
) {
    let w = color.len();
    if !place_samples(ctx, x0, j, w, s) {
        return;
    }
    nearest_triangles(ctx, bin, (x0, j), w, s);
    shade_samples(ctx, color, depth, s);
}

/// The row's pixels to render (`w` from `x0` in row `j`, those the mask holds) and their
/// stratified sample positions, exact and in the rasterizer's fixed point; the samples' depth
/// and triangle reset. `false` when the row has no pixel to render.
fn place_samples(ctx: &Context, x0: u32, j: u32, w: usize, s: &mut Scratch) -> bool {
    let [nx, ny] = ctx.strata.map(|k| k as usize);
    let spp = nx * ny;
    s.pixels.clear();
    let row = j as usize * ctx.settings.width as usize + x0 as usize;
    s.pixels
        .extend((0..w as u32).filter(|&p| ctx.active.is_none_or(|a| a[row + p as usize])));
    if s.pixels.is_empty() {
        return false;
    }
    let count = s.pixels.len() * spp;
    s.pos.clear();
    s.fixed.clear();
    let (inv_nx, inv_ny) = (1.0 / nx as f64, 1.0 / ny as f64);
    for &p in &s.pixels {
        let i = x0 + p;
        let mut rng = SplitMix64::for_pixel(ctx.seed, i, j);
        for sy in 0..ny {
            for sx in 0..nx {
                let x = f64::from(i) + (sx as f64 + rng.next_f64()) * inv_nx;
                let y = f64::from(j) + (sy as f64 + rng.next_f64()) * inv_ny;
                s.pos.push(DVec2::new(x, y));
                let f = SUBPIXEL as f64;
                s.fixed
                    .push([(x * f).round() as i64, (y * f).round() as i64]);
            }
        }
    }
    s.depth.clear();
    s.depth.resize(count, f32::INFINITY);
    s.winner.clear();
    s.winner.resize(count, u32::MAX);
    true
}

/// For every sample of the row `j` pixels from `x0` (`w` wide), the nearest triangle of `bin`
/// that covers it (by the edge functions in fixed point, the depth in `f32`).
fn nearest_triangles(ctx: &Context, bin: &[u32], (x0, j): (u32, u32), w: usize, s: &mut Scratch) {
    let spp = ctx.strata[0] as usize * ctx.strata[1] as usize;
    let x1 = x0 + w as u32 - 1;
    for &id in bin {
        let t = &ctx.setups[id as usize];
        let [bi0, bj0, bi1, bj1] = t.sample_bbox;
        if j < bj0 || j > bj1 {
            continue;
        }
        let (i_lo, i_hi) = (bi0.max(x0), bi1.min(x1));
        if i_lo > i_hi {
            continue;
        }
        let q_lo = s.pixels.partition_point(|&p| x0 + p < i_lo);
        let q_hi = s.pixels.partition_point(|&p| x0 + p <= i_hi);
        for k in q_lo * spp..q_hi * spp {
            let [xf, yf] = s.fixed[k];
            let e = &t.edges;
            if (e[0].at(xf, yf) | e[1].at(xf, yf) | e[2].at(xf, yf)) >= 0 {
                let p = s.pos[k];
                let z = t.depth_at(p.x, p.y) as f32;
                if z < s.depth[k] {
                    s.depth[k] = z;
                    s.winner[k] = id;
                }
            }
        }
    }
}

/// Each pixel's mean over its samples: the nearest triangle's shaded colour, or the background
/// (the environment along the sample's ray, where it is the background); the pixel's depth is its
/// nearest sample's.
fn shade_samples(ctx: &Context, color: &mut [[f32; 4]], depth: &mut [f32], s: &Scratch) {
    let spp = ctx.strata[0] as usize * ctx.strata[1] as usize;
    let background = Vec4::from_array(ctx.settings.background);
    let inv_spp = 1.0 / spp as f32;
    for (q, &p) in s.pixels.iter().enumerate() {
        let (out, nearest) = (&mut color[p as usize], &mut depth[p as usize]);
        let mut sum = Vec4::ZERO;
        for k in q * spp..(q + 1) * spp {
            let id = s.winner[k];
            if id == u32::MAX {
                sum += match &ctx.background {
                    Some((env, rays)) => {
                        let pos = s.pos[k];
                        rays.direction(pos.x, pos.y).map_or(background, |d| {
                            env.radiance(d, [DVec3::ZERO; 2], true, false).0.extend(1.0)
                        })
                    }
                    None => background,
                };
                continue;
            }
            *nearest = nearest.min(s.depth[k]);
            let t = &ctx.setups[id as usize];
            let dc = &ctx.draws[t.draw as usize];
            let pos = s.pos[k];
            let lambda = t.lambda_at(pos.x, pos.y, Perspective::Correct);
            let uv = match dc.mapped(t) {
                Some(m) => m.uv(lambda, None).0,
                None => {
                    let uvs = dc.uvs(t);
                    uvs[0] * lambda.x + uvs[1] * lambda.y + uvs[2] * lambda.z
                }
            };
            let fp = dc.footprint(uv, DVec2::ZERO, DVec2::ZERO);
            let tex = dc.sampler.sample(dc.texture, &fp);
            let shader = Shader {
                draw: dc,
                lighting: ctx.lighting.as_ref(),
                count: false,
            };
            let p = ShadingPoint {
                verts: dc.vertices(t),
                lambda,
                dlambda: [DVec3::ZERO; 2],
                fp,
            };
            let (c, _) = shade(&shader, &p, tex);
            sum += Vec4::from_array(c);
        }
        *out = (sum * inv_spp).to_array();
    }
}

#[cfg(test)]
mod tests {
    use super::square_strata;

    #[test]
    fn stratifications() {
        assert_eq!(square_strata(256), [16, 16]);
        assert_eq!(square_strata(512), [16, 32]);
        assert_eq!(square_strata(1024), [32, 32]);
        assert_eq!(square_strata(1), [1, 1]);
        assert_eq!(square_strata(7), [1, 7]);
        assert_eq!(square_strata(12), [3, 4]);
    }
}
