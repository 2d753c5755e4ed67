//! Screen tiles: binning triangles to 64x64 tiles and rasterising the tiles in parallel (rayon).
//!
//! Design decisions:
//! - Every frame buffer is split, without copying, into per-tile row slices (`chunks_mut`), so tiles
//!   are written in place by whichever thread renders them; no locks, no `unsafe` here, no final
//!   copy. Except for a frame that holds its clear and is larger than the last-level cache
//!   ([`crate::Streaming`]): its tiles are drawn in per-thread scratch and copied into their row
//!   slices with non-temporal stores (`texel_texture::engine::dispatch::stream_copy`). The split is made
//!   per band of `TILE` rows by the thread that renders the band's tiles: made serially up front,
//!   the row lists of a 4K frame (2 040 tiles) would hold back its frames (docs/decisions.md).
//! - Each tile processes its triangles in submission order (draw, then triangle, then sub-triangle)
//!   and every per-pixel computation depends only on the pixel, the triangle and the tile (the
//!   `UvPlanes` anchor), never on the thread or the order tiles run in, so the image is bit for bit
//!   the same for any thread count and any scheduling.
//! - Fragments are depth-tested (`z < depth`, `f32`, `+inf` cleared) before any interpolation or
//!   sampling, so hidden fragments cost only their edge and depth test.
//! - Coverage in the analytic mode steps the three integer edge functions incrementally along each
//!   row (three adds per pixel); the colour view's spans instead solve each row's covered run in
//!   integers (per edge, `e + m step >= 0` for `m` from a floor division: exactly the pixels the
//!   stepping accepts) and depth-test the run in one loop that vectorises; the quad mode evaluates 2x2 aligned quads (tiles have even origins,
//!   so quads never straddle tiles) and interpolates all four pixels of a touched quad.
//! - Triangle setups run in parallel chunks ([`crate::setup`]'s `setup_chunks`) and are binned in
//!   the chunks they are computed in (the bins hold references; binning itself is serial), never
//!   concatenated: a mesh's setups (33 MB for 100k triangles) copied into one buffer above glibc's
//!   largest `mmap` threshold would be mapped and faulted in afresh for every frame.
//!
//! Row-span batching: in the colour view without texel counting, a triangle's covered,
//! depth-passing fragments in a tile are gathered into structure-of-arrays scratch (`Span`, one
//! per thread, reused by every tile and frame it renders, never cleared per triangle): up to 256
//! fragments over as many rows as fit,
//! each fragment carrying its row. The span is then interpolated stage by stage (`1/w`, `u'` and
//! `v'` and their derivatives from the triangle's `f32` `UvPlanes` re-anchored in the tile, eight
//! lanes with AVX2; the `f64` barycentrics only where shading or a sphere mapping reads them;
//! each stage a branch-free loop the compiler vectorises),
//! sampled by one `Sampler::sample_batch` call, then shaded and written: a row whose whole run
//! passed the depth test is written as slices (the encode in lanes, the depths a copy), other rows
//! fragment by fragment. Each stage performs the per-pixel path's operations in the same order, so
//! images are bit for bit the per-pixel path's (`tests/threads.rs`, also on grids of small
//! triangles, head-on and tilted, and on draws that cross in depth). Why: the per-pixel
//! path is latency-bound (one long chain per pixel: `1/w` division, footprint, `log2`, level,
//! texel loads, blend), so cutting instructions alone does not move the wall time; batching lets
//! the independent lod computations of a span overlap, and gathering several rows samples a small
//! triangle in one `sample_batch` call instead of one per row (the sampler runs calls of at most
//! 16 footprints with 16-sample scratch). The periodic `uv` reduction multiplies by the exact
//! reciprocal of the period instead of dividing. The planes' anchor is chosen from the triangle's
//! box in the whole tile, not the scissored range, so a scissor never changes a pixel. When the
//! sampler ignores derivatives (`Sampler::uses_derivatives`: nearest, bilinear or a cubic filter
//! without mipmaps, `mag_filter == min_filter`), footprints are not captured and no material may
//! need them, the span skips them and hands the sampler `u` and `v` alone
//! (`FootprintLanes::points`: zero derivatives). The span's footprints reach the sampler as
//! lanes, one slice per field, never as structs (docs/decisions.md). Frames are reusable
//! (`render_into`, `draw_into`).
//!
//! Frame times and the mesh's triangle rate are in docs/benchmarks.md; the profiles, and how each
//! of these decisions moved them, are in docs/decisions.md.

use std::cell::Cell;

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use texel_texture::base::color::{
    rgba_to_unorm8, rgba_to_unorm8_slice, srgb8_encoder, unorm8_table, Srgb8Encoder,
};
use texel_texture::engine::dispatch::{self, Kernel, StreamElement};
use texel_texture::{BoundSampler, Footprint, FootprintLanes, Lanes, SpanKind, Wants};

use crate::draw::DrawCall;
use crate::environment::{Environment, ViewRays};
use crate::frame::{Clear, Frame};
use crate::interp::{self, quad_differences, UvPlanes};
use crate::point::ShadingPoint;
use crate::settings::{ColorTarget, Derivatives, Perspective, Precision, RenderSettings, View};
use crate::setup::{pixel_center_fixed, setup_chunks, TriangleSetup, SUBPIXEL};
use crate::shade::{shade, DrawContext, Lighting, MappedTriangle, Shader, UvSource};
use crate::views;
use crate::RasterError;

/// Tile side in pixels (even, so 2x2 quads never straddle tiles).
pub const TILE: u32 = 64;

/// Number of tiles across and down a `width x height` frame.
pub(crate) fn tile_counts(width: u32, height: u32) -> (u32, u32) {
    (width.div_ceil(TILE), height.div_ceil(TILE))
}

/// For each tile (row-major), the indices of the setups whose box (`bbox` of the setup: the
/// pixel-centre box for the rasterizer, the sample box for the reference) overlaps it, in order.
pub(crate) fn bin<'s, T: Copy>(
    setups: impl IntoIterator<Item = &'s TriangleSetup>,
    width: u32,
    height: u32,
    bbox: impl Fn(&TriangleSetup) -> Option<[u32; 4]>,
    item: impl Fn(usize, &'s TriangleSetup) -> T,
) -> Vec<Vec<T>> {
    let (tx, ty) = tile_counts(width, height);
    let mut bins = vec![Vec::new(); (tx * ty) as usize];
    for (s, t) in setups.into_iter().enumerate() {
        let Some([i0, j0, i1, j1]) = bbox(t) else {
            continue;
        };
        let it = item(s, t);
        for by in j0 / TILE..=j1 / TILE {
            for bx in i0 / TILE..=i1 / TILE {
                bins[(by * tx + bx) as usize].push(it);
            }
        }
    }
    bins
}

/// Split a row-major `width`-wide buffer into per-tile lists of row slices (row-major tile order).
/// An empty buffer gives empty lists.
pub(crate) fn split_rows<T>(buf: &mut [T], width: u32, height: u32) -> Vec<Vec<&mut [T]>> {
    let (tx, ty) = tile_counts(width, height);
    if buf.is_empty() {
        return (0..tx * ty).map(|_| Vec::new()).collect();
    }
    // Each tile's list allocated once at its row count (grown by pushes, a list of 64 rows is
    // allocated once and reallocated four times: 8 160 reallocations per buffer of a 4K frame).
    let rows = |k: u32| TILE.min(height - (k / tx) * TILE) as usize;
    let mut tiles: Vec<Vec<&mut [T]>> = (0..tx * ty).map(|k| Vec::with_capacity(rows(k))).collect();
    for (j, row) in buf.chunks_mut(width as usize).enumerate() {
        let band = j as u32 / TILE;
        for (b, seg) in row.chunks_mut(TILE as usize).enumerate() {
            tiles[(band * tx) as usize + b].push(seg);
        }
    }
    tiles
}

/// One tile's share of the frame's buffers.
struct TileTarget<'f> {
    x0: u32,
    y0: u32,
    w: u32,
    h: u32,
    /// The colour target's format: which of `color` and `color8` holds rows.
    target: ColorTarget,
    color: Vec<&'f mut [[f32; 4]]>,
    color8: Vec<&'f mut [[u8; 4]]>,
    depth: Vec<&'f mut [f32]>,
    texels: Vec<&'f mut [u32]>,
    footprints: Vec<&'f mut [Footprint]>,
}

impl TileTarget<'_> {
    /// The tile's pixels inside `settings`' scissor, `[i0, j0, i1, j1]` with exclusive ends;
    /// `None` when the tile lies outside it.
    #[inline(always)]
    fn scissored(&self, settings: &RenderSettings) -> Option<[u32; 4]> {
        let [sx0, sy0, sx1, sy1] = settings.scissor_rect();
        let (i0, j0) = (self.x0.max(sx0), self.y0.max(sy0));
        let (i1, j1) = ((self.x0 + self.w).min(sx1), (self.y0 + self.h).min(sy1));
        (i0 < i1 && j0 < j1).then_some([i0, j0, i1, j1])
    }

    /// Write a fragment's colour and depth at tile pixel `(li, lj)`, encoding the colour for an
    /// 8-bit target.
    #[inline(always)]
    fn put(&mut self, li: usize, lj: usize, color: [f32; 4], z: f32) {
        if self.target.is_8bit() {
            self.color8[lj][li] = self.target.encode(color);
        } else {
            self.color[lj][li] = color;
        }
        self.depth[lj][li] = z;
    }
}

/// Everything shared by the tiles of one frame.
struct Context<'a> {
    settings: &'a RenderSettings<'a>,
    draws: Vec<DrawContext<'a>>,
    lighting: Option<Lighting<'a>>,
    counting: bool,
    capture: bool,
    /// The environment's camera rays, when it is the background of a colour view.
    background: Option<(Environment<'a>, ViewRays)>,
    /// Per draw: how its colour-view fragments are sampled ([`Route::of`]).
    routes: Vec<Route<'a>>,
    /// The frame's clear (colour as the target stores it, depth `+inf`) when its tiles are drawn
    /// in scratch and streamed out ([`Frame::draw_streams`]); `None` to draw in place.
    stream: Option<Clear>,
}

impl Context<'_> {
    /// Whether `dc`'s fragments are shaded (`shade` reads their barycentrics and footprints): a
    /// material, vertex colours or lights. Where not, the colour is the sample, and a span skips
    /// the barycentrics (`flush_span`).
    #[inline(always)]
    fn shades(&self, dc: &DrawContext) -> bool {
        !dc.unshaded() || self.lighting.is_some()
    }
}

/// How a draw's colour-view fragments get their texture colour: its sampler bound to its
/// texture for the frame, and whether the bytes a span gets are written as they are.
struct Route<'a> {
    bound: BoundSampler<'a>,
    copy: bool,
}

impl<'a> Route<'a> {
    /// Draw `dc`'s route in a frame of `settings` (lit or not) with colour target `target`.
    ///
    /// Its samples may be written as they are (`copy`) when nothing changes them — the colour
    /// view, no lights, no material, white vertex colours ([`DrawContext::unshaded`]) — and the
    /// target stores colour as the texture stores texels: the target's encoder then gives back
    /// the texture's bytes for every code, so copying them leaves the image unchanged. The
    /// sampler then hands over the stored bytes where it reads one texel, and under
    /// [`Precision::Gpu`] its fixed-point codes where they apply ([`texel_texture::Sampler::bind`]).
    fn of(settings: &RenderSettings, lit: bool, target: ColorTarget, dc: &DrawContext<'a>) -> Self {
        let color = settings.view == View::Color;
        let copy = color && !lit && dc.unshaded() && target.stores_like(dc.texture.format());
        let wants = Wants {
            stored_bytes: copy,
            fixed8: color && settings.precision == Precision::Gpu,
        };
        Route {
            bound: dc.sampler.bind(dc.texture, wants),
            copy,
        }
    }
}

/// What the fragment stage needs besides the pixel: barycentrics and the footprint.
struct Fragment {
    lambda: DVec3,
    /// `lambda`'s derivatives per pixel right and down.
    dlambda: [DVec3; 2],
    fp: Footprint,
    z: f32,
}

/// Draw into `frame` (already the right size, see [`Frame::matches`]) on the current rayon pool;
/// validation is the caller's.
pub(crate) fn draw_frame(
    settings: &RenderSettings,
    draws: &[DrawCall],
    frame: &mut Frame,
) -> Result<(), RasterError> {
    let (width, height) = (settings.width, settings.height);
    let setups = setup_chunks(settings, draws)?;
    let bins = bin(setups.iter().flatten(), width, height, |t| t.bbox, |_, t| t);
    let counting = settings.counts_texels();
    let capture = settings.capture_footprints;
    let draws: Vec<DrawContext> = draws.iter().map(DrawContext::new).collect();
    let lighting = Lighting::of(settings, false);
    let routes = draws
        .iter()
        .map(|dc| Route::of(settings, lighting.is_some(), frame.target, dc))
        .collect();
    // The clear the frame holds (that of its reset, whatever `settings.background` says now).
    let stream = frame.streamed_clear();
    // From here the frame's buffers are written: the next draw must load them.
    frame.forget_clear();
    let ctx = Context {
        settings,
        draws,
        lighting,
        counting,
        capture,
        routes,
        stream,
        background: settings
            .environment
            .filter(|_| settings.view == View::Color)
            .and_then(|e| Some((e, e.background_rays(width, height)?))),
    };
    let (tx, ty) = tile_counts(width, height);
    // Bands of `TILE` rows, each split into its tiles' row lists by the thread that renders it
    // (`Band::tiles`).
    let mut color = band_slices(&mut frame.color, width, ty);
    let mut color8 = band_slices(&mut frame.color8, width, ty);
    let mut depth = band_slices(&mut frame.depth, width, ty);
    let mut texels = band_slices(&mut frame.texels_read, width, ty);
    let mut footprints = band_slices(&mut frame.footprints, width, ty);
    let bands: Vec<Band> = (0..ty)
        .map(|y| Band {
            y0: y * TILE,
            color: color.next().unwrap_or_default(),
            color8: color8.next().unwrap_or_default(),
            depth: depth.next().unwrap_or_default(),
            texels: texels.next().unwrap_or_default(),
            footprints: footprints.next().unwrap_or_default(),
        })
        .collect();
    let target = frame.target;
    bands
        .into_par_iter()
        .zip(bins.par_chunks(tx as usize))
        .with_max_len(1)
        .for_each(|(band, bins)| {
            band.tiles((width, height), target)
                .par_iter_mut()
                .zip(bins.par_iter())
                .with_max_len(1)
                .for_each(|(tile, bin)| raster_tile(&ctx, tile, bin));
        });
    Ok(())
}

/// One band of [`TILE`] rows (the last may be shorter) of every frame buffer, starting at row
/// `y0`; a buffer the frame does not keep is empty.
struct Band<'f> {
    y0: u32,
    color: &'f mut [[f32; 4]],
    color8: &'f mut [[u8; 4]],
    depth: &'f mut [f32],
    texels: &'f mut [u32],
    footprints: &'f mut [Footprint],
}

impl<'f> Band<'f> {
    /// The band's tiles, left to right, for a `width x height` frame with colour target
    /// `target`: each buffer split into per-tile row lists ([`split_rows`]) by the thread that
    /// renders the band (built serially up front for the whole frame, the lists of a 4K frame's
    /// 2 040 tiles would slow its frames, docs/decisions.md).
    fn tiles(self, (width, height): (u32, u32), target: ColorTarget) -> Vec<TileTarget<'f>> {
        let rows = TILE.min(height - self.y0);
        let mut color = split_rows(self.color, width, rows).into_iter();
        let mut color8 = split_rows(self.color8, width, rows).into_iter();
        let mut depth = split_rows(self.depth, width, rows).into_iter();
        let mut texels = split_rows(self.texels, width, rows).into_iter();
        let mut footprints = split_rows(self.footprints, width, rows).into_iter();
        let tx = tile_counts(width, height).0;
        (0..tx)
            .map(|bx| TileTarget {
                x0: bx * TILE,
                y0: self.y0,
                w: TILE.min(width - bx * TILE),
                h: rows,
                target,
                color: color.next().unwrap_or_default(),
                color8: color8.next().unwrap_or_default(),
                depth: depth.next().unwrap_or_default(),
                texels: texels.next().unwrap_or_default(),
                footprints: footprints.next().unwrap_or_default(),
            })
            .collect()
    }
}

/// A row-major `width`-wide buffer as `bands` slices of `TILE` rows each (the last may be
/// shorter); an empty buffer as `bands` empty slices.
fn band_slices<T>(buf: &mut [T], width: u32, bands: u32) -> impl Iterator<Item = &mut [T]> {
    let len = (width * TILE).max(1) as usize;
    let empty = std::iter::repeat_with(|| &mut [][..]);
    buf.chunks_mut(len).chain(empty).take(bands as usize)
}

/// Rasterise one tile: in place, or in scratch streamed out when the frame holds its clear and
/// streams ([`Context::stream`]).
fn raster_tile(ctx: &Context, tile: &mut TileTarget, bin: &[&TriangleSetup]) {
    match ctx.stream {
        Some(clear) => streamed_tile(ctx, tile, bin, clear),
        None => tile_in_place(ctx, tile, bin),
    }
}

/// Per-thread scratch for one streamed tile ([`streamed_tile`]): colour (the target's buffer;
/// the other stays empty) and depth, `TILE * TILE` pixels at most, row-major at the tile's width.
#[derive(Default)]
struct TileScratch {
    color: Vec<[f32; 4]>,
    color8: Vec<[u8; 4]>,
    depth: Vec<f32>,
}

thread_local! {
    /// Each thread's [`TileScratch`], reused by every streamed tile it draws.
    static TILE_SCRATCH: std::cell::RefCell<TileScratch> = std::cell::RefCell::default();
}

/// Copy each scratch row of `src` into the frame row of `dst` with non-temporal stores.
fn stream_rows<T: StreamElement>(dst: &mut [&mut [T]], src: &[&mut [T]]) {
    for (dst, src) in dst.iter_mut().zip(src) {
        dispatch::stream_copy(dst, src);
    }
}

/// Draw a tile of a frame that holds `clear` as a GPU does a cleared target: in the thread's
/// scratch filled with the clear (no read of the frame), then copied into the frame with
/// non-temporal stores (no read either, and the frame's lines do not push the textures out of
/// the cache). A tile no triangle and no background reaches is left alone: the frame holds the
/// clear there already. Bit for bit what [`tile_in_place`] writes into a cleared frame.
fn streamed_tile(ctx: &Context, tile: &mut TileTarget, bin: &[&TriangleSetup], clear: Clear) {
    // Nothing is drawn outside the scissor: such a tile keeps the clear.
    if tile.scissored(ctx.settings).is_none() || (bin.is_empty() && ctx.background.is_none()) {
        return;
    }
    let (w, h) = (tile.w as usize, tile.h as usize);
    let eight = tile.target.is_8bit();
    TILE_SCRATCH.with_borrow_mut(|s| {
        // Each buffer as `n` copies of the clear, in its allocation (`clear` keeps it).
        s.color.clear();
        s.color.resize(if eight { 0 } else { w * h }, clear.color);
        s.color8.clear();
        s.color8.resize(if eight { w * h } else { 0 }, clear.color8);
        s.depth.clear();
        s.depth.resize(w * h, f32::INFINITY);
        let mut scratch = TileTarget {
            x0: tile.x0,
            y0: tile.y0,
            w: tile.w,
            h: tile.h,
            target: tile.target,
            color: s.color.chunks_mut(w.max(1)).collect(),
            color8: s.color8.chunks_mut(w.max(1)).collect(),
            depth: s.depth.chunks_mut(w.max(1)).collect(),
            texels: Vec::new(),
            footprints: Vec::new(),
        };
        tile_in_place(ctx, &mut scratch, bin);
        stream_rows(&mut tile.color, &scratch.color);
        stream_rows(&mut tile.color8, &scratch.color8);
        stream_rows(&mut tile.depth, &scratch.depth);
        // Before the band's join hands the frame to another thread.
        dispatch::stream_fence();
    });
}

/// Rasterise one tile into `tile`'s buffers, on the best instruction set the CPU has
/// ([`texel_texture::engine::dispatch`]), then show the environment where nothing was drawn.
fn tile_in_place(ctx: &Context, tile: &mut TileTarget, bin: &[&TriangleSetup]) {
    dispatch::run(TileJob { ctx, tile, bin });
    if let Some((env, rays)) = &ctx.background {
        background_tile(ctx, env, rays, tile);
    }
}

/// Show the environment in the tile's pixels (inside the scissor) that no fragment covers; their
/// depth stays `+inf`. Texels are counted and footprints captured as for fragments.
fn background_tile(ctx: &Context, env: &Environment, rays: &ViewRays, tile: &mut TileTarget) {
    let Some([i0, j0, i1, j1]) = tile.scissored(ctx.settings) else {
        return;
    };
    for j in j0..j1 {
        for i in i0..i1 {
            let (li, lj) = ((i - tile.x0) as usize, (j - tile.y0) as usize);
            if tile.depth[lj][li] < f32::INFINITY {
                continue;
            }
            let Some((d, dd)) = rays.differentials(i, j) else {
                continue;
            };
            let (layer, fp) = env.footprint(d, dd);
            let (c, n) = env.radiance_at(layer, &fp, false, ctx.counting);
            let color = [c.x, c.y, c.z, 1.0];
            if tile.target.is_8bit() {
                tile.color8[lj][li] = tile.target.encode(color);
            } else {
                tile.color[lj][li] = color;
            }
            if ctx.counting {
                tile.texels[lj][li] = n;
            }
            if ctx.capture {
                tile.footprints[lj][li] = fp;
            }
        }
    }
}

/// [`raster_tile`]'s arguments, as the dispatcher's unit of work.
struct TileJob<'j, 'a, 'f, 's> {
    ctx: &'j Context<'a>,
    tile: &'j mut TileTarget<'f>,
    bin: &'j [&'s TriangleSetup],
}

impl Kernel for TileJob<'_, '_, '_, '_> {
    type Output = ();
    #[inline(always)]
    fn run(self, lanes: Lanes) {
        raster_tile_body(self.ctx, self.tile, self.bin, lanes);
    }
}

/// [`raster_tile`]'s work, inlined into each instruction set's copy.
#[inline(always)]
fn raster_tile_body(ctx: &Context, tile: &mut TileTarget, bin: &[&TriangleSetup], lanes: Lanes) {
    // The tile's pixels inside the scissor, ends exclusive.
    let Some([ti0, tj0, ti1, tj1]) = tile.scissored(ctx.settings) else {
        return;
    };
    let batched = ctx.settings.view == View::Color && !ctx.counting;
    let mut span = if batched {
        let mut span = Span::take();
        span.lanes = lanes;
        Some(span)
    } else {
        None
    };
    for &t in bin {
        let Some([bi0, bj0, bi1, bj1]) = t.bbox else {
            continue;
        };
        let (i_lo, i_hi) = (bi0.max(ti0), bi1.min(ti1 - 1));
        let (j_lo, j_hi) = (bj0.max(tj0), bj1.min(tj1 - 1));
        if i_lo > i_hi || j_lo > j_hi {
            continue;
        }
        let range = [i_lo, j_lo, i_hi, j_hi];
        // Where `uv`'s planes are anchored: the triangle's box in the whole tile, so that a
        // scissor does not change a pixel.
        let home = [
            bi0.max(tile.x0),
            bj0.max(tile.y0),
            bi1.min(tile.x0 + tile.w - 1),
            bj1.min(tile.y0 + tile.h - 1),
        ];
        let source = ctx.draws[t.draw as usize].uv_source(t, ctx.settings.perspective, home);
        match (ctx.settings.derivatives, span.as_deref_mut()) {
            (Derivatives::Analytic, Some(span)) => {
                raster_pixels_batched(ctx, tile, (t, &source), range, span)
            }
            (Derivatives::Analytic, None) => raster_pixels(ctx, tile, (t, &source), range),
            (Derivatives::Quad, _) => raster_quads(ctx, tile, (t, &source), range),
        }
    }
    if let Some(span) = span {
        span.give_back();
    }
}

/// Analytic derivatives: walk the pixels of `range`, stepping the edge functions along rows.
#[inline(always)]
fn raster_pixels(
    ctx: &Context,
    tile: &mut TileTarget,
    (t, source): (&TriangleSetup, &UvSource),
    range: [u32; 4],
) {
    let [i_lo, j_lo, i_hi, j_hi] = range;
    let dc = &ctx.draws[t.draw as usize];
    let perspective = ctx.settings.perspective;
    let step = t.edges.map(|e| e.a * SUBPIXEL);
    let x_start = pixel_center_fixed(i_lo);
    for j in j_lo..=j_hi {
        let y_fixed = pixel_center_fixed(j);
        let mut e = t.edges.map(|e| e.at(x_start, y_fixed));
        let y = f64::from(j) + 0.5;
        let lj = (j - tile.y0) as usize;
        for i in i_lo..=i_hi {
            if (e[0] | e[1] | e[2]) >= 0 {
                let x = f64::from(i) + 0.5;
                let li = (i - tile.x0) as usize;
                let z = t.depth_at(x, y) as f32;
                if z < tile.depth[lj][li] {
                    let b = t.barycentrics(x, y, perspective);
                    let fp = match source {
                        UvSource::Mapped(m) => {
                            let (uv, dx, dy) = m.uv(b.lambda, Some([b.dx, b.dy]));
                            dc.footprint(uv, dx, dy)
                        }
                        UvSource::Planes(p) => p.footprint(i, j),
                    };
                    let f = Fragment {
                        lambda: b.lambda,
                        dlambda: [b.dx, b.dy],
                        fp,
                        z,
                    };
                    write_fragment(ctx, dc, t, tile, li, lj, &f);
                }
            }
            e[0] += step[0];
            e[1] += step[1];
            e[2] += step[2];
        }
    }
}

/// Pixels in a row span of a tile.
const SPAN: usize = 4 * TILE as usize;

/// Structure-of-arrays scratch for one row span of one triangle, reused across the spans and
/// triangles of a tile (no allocation or clearing per triangle). Each stage below is a short loop
/// over `0..n` with no branches and no calls, which the compiler vectorises.
struct Span {
    /// Covered, depth-passing fragments in the span.
    n: usize,
    /// Their column within the tile.
    li: [u32; SPAN],
    /// Their row within the tile.
    lj: [u32; SPAN],
    /// Their depth.
    z: [f32; SPAN],
    /// Their pixel-centre `x` and `y` (filled by `barycentrics` from the rows and columns).
    x: [f64; SPAN],
    y: [f64; SPAN],
    /// `1 / r` (perspective) or 1 (affine).
    inv_r: [f64; SPAN],
    /// Barycentrics.
    l: [[f64; SPAN]; 3],
    /// Their x and y derivatives (zero unless the footprint or a material needs them).
    ldx: [[f64; SPAN]; 3],
    ldy: [[f64; SPAN]; 3],
    /// Their offsets from the [`UvPlanes`] anchor and `1 / r` ([`UvPlanes`]).
    ox: [f32; SPAN],
    oy: [f32; SPAN],
    inv: [f32; SPAN],
    /// The sampler's input, as lanes ([`FootprintLanes`]): `u` and `v` (first `u'`, `v'` of
    /// [`UvPlanes`], then reduced in place), and the derivatives `[dudx, dudy, dvdx, dvdy]`,
    /// written only where `deriv` says they are read.
    u: [f32; SPAN],
    v: [f32; SPAN],
    d: [[f32; SPAN]; 4],
    /// Whether `d` holds the span's derivatives. Else `d` holds stale values that nothing
    /// reads: the span's footprints ([`Span::footprints`], [`Span::footprint`]) then have zero
    /// derivatives. Set by both footprint stages, before anything reads the span.
    deriv: bool,
    /// Rows gathered so far: `(first, end, contiguous)` fragment ranges, one per row, in order.
    run: [(u32, u32, bool); SPAN],
    runs: usize,
    /// The sampler's output.
    texs: [[f32; 4]; SPAN],
    /// The stored-bytes and fixed-point paths' output ([`Route`]).
    bytes: [[u8; 4]; SPAN],
    /// The sampler's quad kernel on the copy this tile runs on ([`Kernel::run`]).
    lanes: Lanes,
}

thread_local! {
    /// Each thread's span scratch: made (and zeroed, 48 KB) once per thread and reused by every
    /// tile the thread renders, where a fresh one per tile cost its allocation and clearing.
    static SPARE_SPAN: Cell<Option<Box<Span>>> = const { Cell::new(None) };
}

impl Span {
    /// This thread's spare span, or a new one.
    fn take() -> Box<Span> {
        SPARE_SPAN.with(Cell::take).unwrap_or_else(Span::new)
    }

    /// Keep this span for the thread's next tile.
    fn give_back(self: Box<Span>) {
        SPARE_SPAN.with(|s| s.set(Some(self)));
    }

    fn new() -> Box<Span> {
        Box::new(Span {
            n: 0,
            li: [0; SPAN],
            lj: [0; SPAN],
            z: [0.0; SPAN],
            x: [0.0; SPAN],
            y: [0.0; SPAN],
            inv_r: [0.0; SPAN],
            l: [[0.0; SPAN]; 3],
            ldx: [[0.0; SPAN]; 3],
            ldy: [[0.0; SPAN]; 3],
            ox: [0.0; SPAN],
            oy: [0.0; SPAN],
            inv: [0.0; SPAN],
            run: [(0, 0, false); SPAN],
            runs: 0,
            u: [0.0; SPAN],
            v: [0.0; SPAN],
            d: [[0.0; SPAN]; 4],
            deriv: false,
            texs: [[0.0; 4]; SPAN],
            bytes: [[0; 4]; SPAN],
            lanes: Lanes::scalar(),
        })
    }

    /// The span's footprints, as the sampler takes them: a function of the fields it reads, so
    /// that the sampler's output fields can be borrowed beside it.
    #[inline(always)]
    fn footprints<'s>(
        (n, deriv): (usize, bool),
        u: &'s [f32; SPAN],
        v: &'s [f32; SPAN],
        d: &'s [[f32; SPAN]; 4],
    ) -> FootprintLanes<'s> {
        let (u, v) = (&u[..n], &v[..n]);
        if deriv {
            let [a, b, c, d] = d;
            FootprintLanes::new(u, v, [&a[..n], &b[..n], &c[..n], &d[..n]])
        } else {
            FootprintLanes::points(u, v)
        }
    }

    /// Fragment `k`'s footprint (zero derivatives unless `deriv`): what
    /// `Span::footprints(..).get(k)` gives, read from the arrays directly. Through
    /// `FootprintLanes::get` (six bounds-checked slices and a match per fragment) the shaded
    /// `builtin:knot` retires more instructions a frame (docs/decisions.md).
    #[inline(always)]
    fn footprint(&self, k: usize) -> Footprint {
        // Indexed lane by lane: `self.d.map(..)` would copy the four lanes (4 KB) per call.
        let d = if self.deriv {
            [self.d[0][k], self.d[1][k], self.d[2][k], self.d[3][k]]
        } else {
            [0.0; 4]
        };
        Footprint {
            u: self.u[k],
            v: self.v[k],
            dudx: d[0],
            dudy: d[1],
            dvdx: d[2],
            dvdy: d[3],
        }
    }

    /// Record the fragments from `k` to `self.n` as one row's run (none if empty); `contiguous`:
    /// their columns follow one another, so their writes are slices.
    #[inline(always)]
    fn push_run(&mut self, k: usize, contiguous: bool) {
        if self.n > k {
            self.run[self.runs] = (k as u32, self.n as u32, contiguous);
            self.runs += 1;
        }
    }

    /// Barycentrics of the span's fragments at their pixel centres, with the derivatives when
    /// asked: [`interp::lambda`] and [`interp::lambda_derivative`], the kernels of
    /// [`TriangleSetup::barycentrics`], staged over the span (so the same bits).
    #[inline(always)]
    fn barycentrics(
        &mut self,
        t: &TriangleSetup,
        perspective: Perspective,
        deriv: bool,
        origin: [u32; 2],
    ) {
        let n = self.n;
        for k in 0..n {
            self.x[k] = f64::from(self.li[k] + origin[0]) + 0.5;
            self.y[k] = f64::from(self.lj[k] + origin[1]) + 0.5;
        }
        let xys = self.x[..n].iter().zip(&self.y[..n]);
        match perspective {
            Perspective::Correct => {
                let r = t.r;
                for (inv, (&x, &y)) in self.inv_r[..n].iter_mut().zip(xys.clone()) {
                    *inv = 1.0 / r.at(x, y);
                }
                for (q, l) in t.q.iter().zip(&mut self.l) {
                    let it = xys.clone().zip(&self.inv_r[..n]);
                    for (l, ((&x, &y), &inv)) in l[..n].iter_mut().zip(it) {
                        *l = interp::lambda(q.at(x, y), inv);
                    }
                }
                if !deriv {
                    // Nothing reads them (no material, a sampler without derivatives): zero,
                    // not left over from an earlier span.
                    self.ldx.iter_mut().for_each(|d| d[..n].fill(0.0));
                    self.ldy.iter_mut().for_each(|d| d[..n].fill(0.0));
                } else {
                    for k in 0..3 {
                        let q = t.q[k];
                        let it = self.l[k][..n].iter().zip(&self.inv_r[..n]);
                        let out = self.ldx[k][..n].iter_mut().zip(&mut self.ldy[k][..n]);
                        for ((dx, dy), (&l, &inv)) in out.zip(it) {
                            *dx = interp::lambda_derivative(q.dx, l, r.dx, inv);
                            *dy = interp::lambda_derivative(q.dy, l, r.dy, inv);
                        }
                    }
                }
            }
            Perspective::Affine => {
                for (a, l) in t.affine.iter().zip(&mut self.l) {
                    for (l, (&x, &y)) in l[..n].iter_mut().zip(xys.clone()) {
                        *l = a.at(x, y);
                    }
                }
                for k in 0..3 {
                    let d = if deriv {
                        t.affine[k]
                    } else {
                        Default::default()
                    };
                    self.ldx[k][..n].fill(d.dx);
                    self.ldy[k][..n].fill(d.dy);
                }
            }
        }
    }

    /// The footprints of the span's fragments under a per-pixel sphere mapping, from their
    /// barycentrics (and, when `deriv`, their derivatives), reduced by [`DrawContext::footprint`]:
    /// not a linear combination, one fragment at a time.
    #[inline(always)]
    fn mapped_footprints(&mut self, dc: &DrawContext, m: &MappedTriangle, deriv: bool) {
        let [l0, l1, l2] = &self.l;
        let [x0, x1, x2] = &self.ldx;
        let [y0, y1, y2] = &self.ldy;
        for k in 0..self.n {
            let lambda = DVec3::new(l0[k], l1[k], l2[k]);
            let dlambda = deriv.then(|| {
                [
                    DVec3::new(x0[k], x1[k], x2[k]),
                    DVec3::new(y0[k], y1[k], y2[k]),
                ]
            });
            let (uv, dx, dy) = m.uv(lambda, dlambda);
            let fp = dc.footprint(uv, dx, dy);
            (self.u[k], self.v[k]) = (fp.u, fp.v);
            if deriv {
                self.d[0][k] = fp.dudx;
                self.d[1][k] = fp.dudy;
                self.d[2][k] = fp.dvdx;
                self.d[3][k] = fp.dvdy;
            }
        }
        self.deriv = deriv;
    }

    /// The footprints of the span's fragments from `uv`'s planes `p`: [`UvPlanes::footprint`]'s
    /// operations, stage by stage over the span in `f32` (eight lanes with AVX2), for a tile
    /// whose top-left pixel is `origin`, into the span's lanes ([`Span::footprints`]). The
    /// derivatives only with `deriv` (set where the sampler uses derivatives, footprints are
    /// captured or a material may need them); without it the span's footprints have zero
    /// derivatives and the lanes are not written. The lanes go to the sampler as they are: no
    /// six-field structs interleaved here and copied back out in the sampler (docs/decisions.md).
    #[inline(always)]
    fn plane_footprints(&mut self, p: &UvPlanes, origin: [u32; 2], deriv: bool) {
        let n = self.n;
        // Tile-local anchor: `li - a` is the frame's `i - anchor`, exactly as `UvPlanes::offset`.
        let (ai, aj) = (
            p.anchor[0] as i32 - origin[0] as i32,
            p.anchor[1] as i32 - origin[1] as i32,
        );
        for k in 0..n {
            self.ox[k] = (self.li[k] as i32 - ai) as f32;
            self.oy[k] = (self.lj[k] as i32 - aj) as f32;
        }
        for k in 0..n {
            self.inv[k] = p.inv_r(self.ox[k], self.oy[k]);
        }
        for k in 0..n {
            let (x, y, inv) = (self.ox[k], self.oy[k], self.inv[k]);
            self.u[k] = p.value(0, x, y, inv);
            self.v[k] = p.value(1, x, y, inv);
        }
        // The derivatives from the unreduced `u'` and `v'` (reducing would break them at a
        // period's edge), then `u` and `v` reduced in place; each loop free of branches.
        if deriv {
            let [dudx, dudy, dvdx, dvdy] = &mut self.d;
            for k in 0..n {
                let (u, v, inv) = (self.u[k], self.v[k], self.inv[k]);
                (dudx[k], dudy[k]) = p.derivatives(0, u, inv);
                (dvdx[k], dvdy[k]) = p.derivatives(1, v, inv);
            }
        }
        for k in 0..n {
            self.u[k] = p.reduce(0, self.u[k]);
            self.v[k] = p.reduce(1, self.v[k]);
        }
        self.deriv = deriv;
    }
}

/// [`raster_pixels`] for the colour view without texel counting: the triangle's covered,
/// depth-passing fragments in the tile are gathered row by row into a [`Span`] (up to [`SPAN`] of
/// them, several rows of a small triangle at once), then interpolated stage by stage over all of
/// them, sampled with one [`texel_texture::Sampler::sample_batch`] call, then shaded and written.
/// The fragments of one triangle are distinct pixels, so deferring their writes changes nothing,
/// and each stage performs the per-pixel path's operations in the same order: the image is bit for
/// bit the per-pixel path's (`tests/threads.rs`). What it buys: the interpolation stages
/// vectorise, the sampler's lod chains pipeline together, and per-call set-up (format, tables,
/// scratch) happens once per batch. Gathering several rows matters for small triangles: one call
/// per row would make three calls of three samples for each triangle of a mesh of 100 352
/// triangles of about nine pixels each.
#[inline(always)]
fn raster_pixels_batched(
    ctx: &Context,
    tile: &mut TileTarget,
    (t, source): (&TriangleSetup, &UvSource),
    range: [u32; 4],
    span: &mut Span,
) {
    let [i_lo, j_lo, i_hi, j_hi] = range;
    let dc = &ctx.draws[t.draw as usize];
    let step = t.edges.map(|e| e.a * SUBPIXEL);
    let x_start = pixel_center_fixed(i_lo);
    // A row adds at most this many fragments.
    let width = (i_hi - i_lo + 1) as usize;
    span.n = 0;
    span.runs = 0;
    for j in j_lo..=j_hi {
        if span.n + width > SPAN {
            flush_span(ctx, tile, t, (dc, source), span);
        }
        let y_fixed = pixel_center_fixed(j);
        let e = t.edges.map(|e| e.at(x_start, y_fixed));
        // The row's covered pixels, `i_lo + m` for `m` in `lo..=hi`: exactly those where every
        // edge function `e + m step` is `>= 0` (integers, solved per edge), so the pixels need no
        // edge test of their own.
        let (mut lo, mut hi) = (0i64, width as i64 - 1);
        for (e, s) in e.into_iter().zip(step) {
            if s > 0 {
                lo = lo.max(-e.div_euclid(s));
            } else if s < 0 {
                hi = hi.min(e.div_euclid(-s));
            } else if e < 0 {
                hi = -1;
            }
        }
        if lo > hi {
            continue;
        }
        let y = f64::from(j) + 0.5;
        let lj = j - tile.y0;
        let depth_row = &tile.depth[lj as usize];
        let n = span.n;
        let len = (hi - lo + 1) as usize;
        let i0 = i_lo + lo as u32;
        let l0 = (i0 - tile.x0) as usize;
        // Depth of the whole run and how many pass, in one loop that vectorises (the pixel
        // index as `i32` converts to `f64` in lanes; the same value as from `u32`).
        let (zs, ds) = (&mut span.z[n..n + len], &depth_row[l0..l0 + len]);
        let mut pass = 0usize;
        for (m, (z, d)) in zs.iter_mut().zip(ds).enumerate() {
            *z = t.depth_at(f64::from((i0 + m as u32) as i32) + 0.5, y) as f32;
            pass += usize::from(*z < *d);
        }
        let (lis, ljs) = (&mut span.li[n..n + len], &mut span.lj[n..n + len]);
        if pass == len {
            for (m, (li, lj_)) in lis.iter_mut().zip(ljs).enumerate() {
                *li = (l0 + m) as u32;
                *lj_ = lj;
            }
            span.n = n + len;
            span.push_run(n, true);
        } else {
            // Compact in place (the write slot never passes the read slot): every fragment is
            // written at slot `w`, which advances only when it passes the depth test.
            let mut w = n;
            for (m, &d) in ds.iter().enumerate() {
                let z = span.z[n + m];
                span.z[w] = z;
                span.li[w] = (l0 + m) as u32;
                span.lj[w] = lj;
                w += usize::from(z < d);
            }
            span.n = w;
            span.push_run(n, false);
        }
    }
    flush_span(ctx, tile, t, (dc, source), span);
}

/// Interpolate, sample, shade and write the `span.n` gathered fragments of triangle `t`, then empty
/// the span.
#[inline(always)]
fn flush_span(
    ctx: &Context,
    tile: &mut TileTarget,
    t: &TriangleSetup,
    (dc, source): (&DrawContext, &UvSource),
    span: &mut Span,
) {
    let n = span.n;
    if n == 0 {
        return;
    }
    // Samplers without mipmaps whose two filters agree ignore the derivatives: skip them unless
    // captured or a material's maps may need them.
    let deriv = ctx.capture || dc.sampler.uses_derivatives() || dc.material.is_some();
    // Barycentrics only where something reads them: shading, or a sphere mapping.
    let shaded = ctx.shades(dc);
    match source {
        UvSource::Mapped(m) => {
            span.barycentrics(t, ctx.settings.perspective, deriv, [tile.x0, tile.y0]);
            span.mapped_footprints(dc, m, deriv);
        }
        UvSource::Planes(p) => {
            if shaded {
                span.barycentrics(t, ctx.settings.perspective, deriv, [tile.x0, tile.y0]);
            }
            span.plane_footprints(p, [tile.x0, tile.y0], deriv);
        }
    }
    let fps = Span::footprints((n, span.deriv), &span.u, &span.v, &span.d);
    let route = &ctx.routes[t.draw as usize];
    let (texs, bytes) = (&mut span.texs[..n], &mut span.bytes[..n]);
    match route.bound.sample_span(span.lanes, fps, texs, bytes) {
        SpanKind::Float => shade_span(ctx, tile, t, dc, span),
        SpanKind::Fixed8 if !route.copy => {
            for (t, b) in span.texs[..n].iter_mut().zip(&span.bytes[..n]) {
                *t = decode_unorm8(*b);
            }
            shade_span(ctx, tile, t, dc, span);
        }
        SpanKind::Stored | SpanKind::Fixed8 => {
            let (color8, depth) = (&mut tile.color8, &mut tile.depth);
            write_rows(span, &span.bytes, color8, depth, Copied);
        }
    }
    if ctx.capture {
        for k in 0..n {
            tile.footprints[span.lj[k] as usize][span.li[k] as usize] = span.footprint(k);
        }
    }
    span.n = 0;
    span.runs = 0;
}

/// Shade and write the span's fragments, whose samples `span.texs` holds.
#[inline(always)]
fn shade_span(
    ctx: &Context,
    tile: &mut TileTarget,
    t: &TriangleSetup,
    dc: &DrawContext,
    span: &mut Span,
) {
    let n = span.n;
    let verts = dc.vertices(t);
    // An unshaded, unlit draw's colour is its sample (`shade` returns `tex` unchanged).
    let shader = Shader {
        draw: dc,
        lighting: ctx.lighting.as_ref(),
        count: false,
    };
    if ctx.shades(dc) {
        for k in 0..n {
            let lambda = DVec3::new(span.l[0][k], span.l[1][k], span.l[2][k]);
            let dlambda = [
                DVec3::new(span.ldx[0][k], span.ldx[1][k], span.ldx[2][k]),
                DVec3::new(span.ldy[0][k], span.ldy[1][k], span.ldy[2][k]),
            ];
            let p = ShadingPoint {
                verts,
                lambda,
                dlambda,
                fp: span.footprint(k),
            };
            span.texs[k] = shade(&shader, &p, span.texs[k]).0;
        }
    }
    // Fragments arrive row by row: look each row's buffers up once per run of equal rows, with
    // the target's format decided once per span.
    let (color8, depth) = (&mut tile.color8, &mut tile.depth);
    let texs = &span.texs;
    match tile.target {
        ColorTarget::Float => write_rows(span, texs, &mut tile.color, depth, Copied),
        ColorTarget::Srgb8 => write_rows(span, texs, color8, depth, srgb8_encoder()),
        ColorTarget::Unorm8 => write_rows(span, texs, color8, depth, Unorm8),
    }
}

/// A unorm8 colour as linear RGBA, `b / 255` (the texture decoding of `Rgba8Unorm`).
#[inline(always)]
fn decode_unorm8(b: [u8; 4]) -> [f32; 4] {
    let table = unorm8_table();
    b.map(|c| table[c as usize])
}

/// How [`write_rows`] turns a value into what the target stores: a trait with always-inlined
/// methods rather than a closure, which the compiler keeps out of line (in the baseline copy, not
/// the tile's x86-64-v3 one; docs/decisions.md).
trait Encode<V, C>: Copy {
    fn encode(self, v: &V) -> C;
    /// `out[k] = encode(values[k])` for a run of one row (same lengths).
    #[inline(always)]
    fn encode_run(self, values: &[V], out: &mut [C]) {
        for (c, v) in out.iter_mut().zip(values) {
            *c = self.encode(v);
        }
    }
}

/// Values stored as they are.
#[derive(Clone, Copy)]
struct Copied;

impl<V: Copy> Encode<V, V> for Copied {
    #[inline(always)]
    fn encode(self, v: &V) -> V {
        *v
    }
}

/// Linear RGBA to unorm8 bytes ([`rgba_to_unorm8`]).
#[derive(Clone, Copy)]
struct Unorm8;

impl Encode<[f32; 4], [u8; 4]> for Unorm8 {
    #[inline(always)]
    fn encode(self, v: &[f32; 4]) -> [u8; 4] {
        rgba_to_unorm8(*v)
    }
    /// The run's channels in one loop that vectorises across pixels ([`rgba_to_unorm8_slice`],
    /// the same bytes) rather than colour by colour, four lanes at a time (docs/decisions.md).
    #[inline(always)]
    fn encode_run(self, values: &[[f32; 4]], out: &mut [[u8; 4]]) {
        rgba_to_unorm8_slice(values, out);
    }
}

/// Linear RGBA to sRGB bytes (`rgba_to_srgb8`), the encoder looked up once per span.
impl Encode<[f32; 4], [u8; 4]> for &Srgb8Encoder {
    #[inline(always)]
    fn encode(self, v: &[f32; 4]) -> [u8; 4] {
        self.encode_rgba(*v)
    }
}

/// Write the span's colours (`values`, through `encode`) and depths into the tile's rows.
#[inline(always)]
fn write_rows<V, C>(
    span: &Span,
    values: &[V],
    color: &mut [&mut [C]],
    depth: &mut [&mut [f32]],
    encode: impl Encode<V, C>,
) {
    for &(k0, k1, contiguous) in &span.run[..span.runs] {
        let (k0, k1) = (k0 as usize, k1 as usize);
        let lj = span.lj[k0] as usize;
        let (color, depth) = (&mut *color[lj], &mut *depth[lj]);
        let (values, zs) = (&values[k0..k1], &span.z[k0..k1]);
        if contiguous {
            // Slices: the encode runs in lanes and the depths are a copy.
            let li = span.li[k0] as usize;
            encode.encode_run(values, &mut color[li..li + values.len()]);
            depth[li..li + zs.len()].copy_from_slice(zs);
        } else {
            for (k, (v, &z)) in values.iter().zip(zs).enumerate() {
                let li = span.li[k0 + k] as usize;
                color[li] = encode.encode(v);
                depth[li] = z;
            }
        }
    }
}

/// Quad derivatives: walk aligned 2x2 quads; a quad with any covered pixel interpolates all four.
#[inline(always)]
fn raster_quads(
    ctx: &Context,
    tile: &mut TileTarget,
    (t, source): (&TriangleSetup, &UvSource),
    range: [u32; 4],
) {
    let [i_lo, j_lo, i_hi, j_hi] = range;
    let dc = &ctx.draws[t.draw as usize];
    let perspective = ctx.settings.perspective;
    for qj in (j_lo & !1..=j_hi).step_by(2) {
        for qi in (i_lo & !1..=i_hi).step_by(2) {
            let mut mask = 0u32;
            let mut z = [0.0f32; 4];
            for k in 0..4u32 {
                let (i, j) = (qi + (k & 1), qj + (k >> 1));
                if i < i_lo || i > i_hi || j < j_lo || j > j_hi {
                    continue;
                }
                let (xf, yf) = (pixel_center_fixed(i), pixel_center_fixed(j));
                if t.edges.iter().all(|e| e.at(xf, yf) >= 0) {
                    let zk = t.depth_at(f64::from(i) + 0.5, f64::from(j) + 0.5) as f32;
                    let (li, lj) = ((i - tile.x0) as usize, (j - tile.y0) as usize);
                    if zk < tile.depth[lj][li] {
                        mask |= 1 << k;
                        z[k as usize] = zk;
                    }
                }
            }
            if mask == 0 {
                continue;
            }
            let lambda: [DVec3; 4] = std::array::from_fn(|k| {
                let x = f64::from(qi + (k as u32 & 1)) + 0.5;
                let y = f64::from(qj + (k as u32 >> 1)) + 0.5;
                t.lambda_at(x, y, perspective)
            });
            // The barycentrics' differences across the quad, as the uv's.
            let dl = quad_differences(lambda.map(|l| l.truncate())).map(|(dx, dy)| {
                let third = |d: DVec2| DVec3::new(d.x, d.y, -d.x - d.y);
                [third(dx), third(dy)]
            });
            let fps: [Footprint; 4] = match source {
                // A per-pixel sphere mapping differences the positions (continuous) and maps the
                // differences through the projection's Jacobian, never differencing u.
                UvSource::Mapped(m) => std::array::from_fn(|k| {
                    let (uv, dx, dy) = m.uv(lambda[k], Some(dl[k]));
                    dc.footprint(uv, dx, dy)
                }),
                UvSource::Planes(p) => p.quad_footprints(qi, qj),
            };
            for k in 0..4usize {
                if mask & (1 << k) != 0 {
                    let (i, j) = (qi + (k as u32 & 1), qj + (k as u32 >> 1));
                    let f = Fragment {
                        lambda: lambda[k],
                        dlambda: dl[k],
                        fp: fps[k],
                        z: z[k],
                    };
                    let (li, lj) = ((i - tile.x0) as usize, (j - tile.y0) as usize);
                    write_fragment(ctx, dc, t, tile, li, lj, &f);
                }
            }
        }
    }
}

/// Shade a fragment that passed the depth test and write it to the tile.
#[inline(always)]
fn write_fragment(
    ctx: &Context,
    dc: &DrawContext,
    t: &TriangleSetup,
    tile: &mut TileTarget,
    li: usize,
    lj: usize,
    f: &Fragment,
) {
    let fp = f.fp;
    // Under `Precision::Gpu` the colour is the fixed-point sample (of the same texels, so the
    // counts are the exact sampler's).
    let mut code = [[0u8; 4]];
    let bound = &ctx.routes[t.draw as usize].bound;
    let fixed = bound.kind() == SpanKind::Fixed8;
    if fixed {
        bound.sample_span(Lanes::scalar(), &[fp], &mut [], &mut code);
    }
    let (mut tex, count) = if ctx.counting {
        dc.sampler.sample_counted(dc.texture, &fp)
    } else if ctx.settings.view == View::Color && !fixed {
        (dc.sampler.sample(dc.texture, &fp), 0)
    } else {
        ([0.0; 4], 0)
    };
    if fixed {
        tex = decode_unorm8(code[0]);
    }
    let lit = ctx.lighting.as_ref();
    // The texels a material's maps read count too (in every view, so the fetches view agrees
    // with the counts of the colour view).
    let (shaded, map_texels) =
        if ctx.settings.view == View::Color || (ctx.counting && lit.is_some()) {
            let shader = Shader {
                draw: dc,
                lighting: lit,
                count: ctx.counting,
            };
            let p = ShadingPoint {
                verts: dc.vertices(t),
                lambda: f.lambda,
                dlambda: f.dlambda,
                fp,
            };
            shade(&shader, &p, tex)
        } else {
            ([0.0; 4], 0)
        };
    let count = count + map_texels;
    let color = match ctx.settings.view {
        View::Color => shaded,
        View::Uv => views::uv_color(f64::from(fp.u), f64::from(fp.v)),
        View::Mip => views::mip_color(dc.sampler, dc.texture, &fp),
        View::Lod => views::lod_color(dc.sampler, dc.texture, &fp),
        View::Aniso => views::aniso_color(dc.texture, &fp),
        View::Fetches => views::fetches_color(count),
        View::Barycentric => views::barycentric_color(f.lambda),
    };
    tile.put(li, lj, color, f.z);
    if ctx.counting {
        tile.texels[lj][li] = count;
    }
    if ctx.capture {
        tile.footprints[lj][li] = fp;
    }
}
