//! The reference with error bars: independent passes, each pixel's standard error, and more
//! samples where the error is still larger than the tolerance.
//!
//! A *pass* is one stratified jittered estimate per pixel ([`crate::reference`]) with its own
//! seed, derived from the plan's seed and the pass number. Passes are independent and identically
//! distributed, so the mean of `K` passes is unbiased and the spread of the pass means estimates
//! its error: with `s^2` the sample variance of the `K` pass means of a channel (linear light),
//! the standard error is `s / sqrt(K)` and the 95 % interval is the mean `± t(K - 1) * s / sqrt(K)`
//! (Student's t quantile, which widens the interval when `K` is small).
//!
//! Convergence is judged on what a person sees: a pixel is converged when, for each of R, G and
//! B, the displayed value (clipped to `[0, 1]`, sRGB-encoded when the display is sRGB) at either
//! end of the interval lies within the tolerance of the displayed mean. A pixel whose interval
//! lies wholly above 1 is converged however wide it is, since the display clips it.
//!
//! The plan's minimum is spent in at least [`MIN_PASSES`] passes (one per sample when it has fewer
//! samples); then, in rounds, every unconverged pixel gets as many passes again as it has (its
//! samples double; the last round adds only what the maximum leaves) until it converges or
//! reaches the maximum, rounded down to whole passes. Every unconverged pixel of a round gets the
//! same passes, so the result depends on the seed only, not on the thread count or the order of
//! work. Each pass is an unbiased estimate; whether a pixel gets more passes depends on the ones it
//! has, so a pixel whose passes all missed a rare bright feature (a glint) shows a small spread,
//! stops early and stays too dark. The error bars cannot see what no pass sampled.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::draw::DrawCall;
use crate::error::RasterError;
use crate::exact::{render_exact, ExactImage};
use crate::frame::Frame;
use crate::reference::{square_strata, with_passes, MAX_SPP_SIDE};
use crate::settings::RenderSettings;
use texel_texture::base::color::displayed as display;
use texel_texture::base::rng::mix64;

/// Passes the minimum sample count is split into (when it has that many samples): enough for a
/// variance estimate with seven degrees of freedom.
pub const MIN_PASSES: u32 = 8;

/// The seed of [`ReferencePlan::default`], the one the command line's references use unless told.
pub const DEFAULT_SEED: u64 = 0x7e_7e1;

/// The largest maximum samples per pixel ([`ReferencePlan::max_spp`]).
pub const MAX_ADAPTIVE_SPP: u32 = 1 << 20;

/// How a reference converges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferencePlan {
    /// Samples every pixel gets, 1 to 4096.
    pub min_spp: u32,
    /// The most samples a pixel gets, `min_spp` to [`MAX_ADAPTIVE_SPP`]; equal to `min_spp`, no
    /// pixel gets more.
    pub max_spp: u32,
    /// Half-width of the 95 % interval of the displayed value, in `[0, 1]` display units, at which
    /// a pixel is converged (`0.5 / 255` is half an 8-bit step).
    pub tolerance: f64,
    /// Whether the display encodes sRGB (otherwise it shows linear values), both clipped to `[0, 1]`.
    pub srgb_display: bool,
    /// Seed of the first pass; two seeds give independent estimates.
    pub seed: u64,
    /// Whether pixels whose visible surface is unlit textured triangles get their integral
    /// computed ([`crate::exact`]) instead of sampled; the others are sampled as the plan says.
    pub exact: bool,
}

/// The tolerance of [`ReferencePlan::default`] in 8-bit steps of the display: half a step.
pub const DEFAULT_TOLERANCE_STEPS: f64 = 0.5;

impl ReferencePlan {
    /// A plan from the figures a user gives: `min_spp` to `max_spp` samples a pixel, converged
    /// within `tolerance_steps` 8-bit steps of the display (sRGB-encoded when `srgb_display`),
    /// jitter from `seed`. Every command, the Python package and the viewer make their plans here.
    ///
    /// # Errors
    /// [`RasterError::MaxSppBelowMin`] when `max_spp < min_spp`,
    /// [`RasterError::InvalidTolerance`] for a negative or non-finite tolerance, and
    /// [`RasterError::InvalidReferencePlan`] for sample counts outside their ranges.
    pub fn new(
        min_spp: u32,
        max_spp: u32,
        tolerance_steps: f64,
        srgb_display: bool,
        seed: u64,
    ) -> Result<Self, RasterError> {
        if max_spp < min_spp {
            return Err(RasterError::MaxSppBelowMin { min_spp, max_spp });
        }
        if !(tolerance_steps.is_finite() && tolerance_steps >= 0.0) {
            return Err(RasterError::InvalidTolerance(tolerance_steps));
        }
        let plan = ReferencePlan {
            min_spp,
            max_spp,
            tolerance: tolerance_steps / 255.0,
            srgb_display,
            seed,
            exact: false,
        };
        check_plan(&plan)?;
        Ok(plan)
    }

    /// The plan with [`ReferencePlan::exact`] set to `exact`.
    pub fn with_exact(self, exact: bool) -> Self {
        ReferencePlan { exact, ..self }
    }

    /// The tolerance in 8-bit steps of the display.
    pub fn tolerance_steps(&self) -> f64 {
        self.tolerance * 255.0
    }
}

impl Default for ReferencePlan {
    fn default() -> Self {
        ReferencePlan {
            min_spp: 256,
            max_spp: 65_536,
            tolerance: DEFAULT_TOLERANCE_STEPS / 255.0,
            srgb_display: true,
            seed: DEFAULT_SEED,
            exact: false,
        }
    }
}

/// Where a converging reference stands, for progress bars.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceStatus {
    /// The round: 0 for the minimum's passes, then 1, 2, ...
    pub round: u32,
    /// Samples per pixel of the pixels being refined, once this round is done.
    pub spp: u32,
    /// Pixels being rendered in this round.
    pub active: u64,
    /// Share of all pixels converged before this round.
    pub converged: f64,
    /// Pixel-passes of this round done.
    pub done: u64,
    /// Pixel-passes of this round in total.
    pub total: u64,
}

/// A reference with its error bars.
#[derive(Clone, Debug)]
pub struct ReferenceEstimate {
    /// The mean colour in linear light (float target) and the nearest depth.
    pub frame: Frame,
    /// Each pixel's standard error of the mean per channel (linear light, RGBA); infinite for a
    /// pixel with fewer than two passes.
    pub std_error: Vec<[f32; 4]>,
    /// Each pixel's half-width of the 95 % interval of the displayed value, the largest over R, G
    /// and B (display units, `[0, 1]`); infinite with fewer than two passes.
    pub display_half_width: Vec<f32>,
    /// Samples each pixel got (0 for an exact pixel).
    pub spp: Vec<u32>,
    /// Whether each pixel's value is its computed integral (standard error 0; its interval
    /// half-width is the arithmetic's bound), not a sampled estimate.
    pub exact: Vec<bool>,
    /// Whether each pixel met the tolerance.
    pub converged: Vec<bool>,
    /// Whether the stop flag ended the work early (each pixel holds whole passes; a pass that was
    /// stopped reached some pixels and not others).
    pub interrupted: bool,
    /// The plan it was made with.
    pub plan: ReferencePlan,
}

impl ReferenceEstimate {
    /// Share of the pixels that met the tolerance (of those `mask` selects, or all).
    pub fn converged_share(&self, mask: Option<&[bool]>) -> f64 {
        share(&self.converged, mask, |&c| c)
    }

    /// Share of the pixels that are exact (of those `mask` selects, or all).
    pub fn exact_share(&self, mask: Option<&[bool]>) -> f64 {
        share(&self.exact, mask, |&e| e)
    }

    /// Mean samples per pixel (of those `mask` selects, or all).
    pub fn mean_spp(&self, mask: Option<&[bool]>) -> f64 {
        masked_mean(&self.spp, mask, |&n| f64::from(n)).unwrap_or(0.0)
    }
}

/// Share of the values `mask` selects (or all) for which `pred` holds; 1 when it selects none.
fn share<T>(values: &[T], mask: Option<&[bool]>, pred: impl Fn(&T) -> bool) -> f64 {
    masked_mean(values, mask, |v| f64::from(u8::from(pred(v)))).unwrap_or(1.0)
}

/// Mean of `f` over the values `mask` selects (or all); `None` when it selects none.
fn masked_mean<T>(values: &[T], mask: Option<&[bool]>, f: impl Fn(&T) -> f64) -> Option<f64> {
    let (mut n, mut sum) = (0u64, 0.0);
    for (i, v) in values.iter().enumerate() {
        if mask.is_none_or(|m| m[i]) {
            n += 1;
            sum += f(v);
        }
    }
    (n > 0).then(|| sum / n as f64)
}

/// The 0.975 quantile of Student's t with `dof` degrees of freedom: the value of the next smaller
/// tabulated degree, rounded to three decimals.
pub fn t_975(dof: u32) -> f64 {
    const TABLE: [(u32, f64); 19] = [
        (1, 12.706),
        (2, 4.303),
        (3, 3.182),
        (4, 2.776),
        (5, 2.571),
        (6, 2.447),
        (7, 2.365),
        (8, 2.306),
        (9, 2.262),
        (10, 2.228),
        (12, 2.179),
        (15, 2.131),
        (20, 2.086),
        (30, 2.042),
        (40, 2.021),
        (60, 2.000),
        (120, 1.980),
        (1000, 1.962),
        (u32::MAX, 1.960),
    ];
    TABLE
        .iter()
        .rev()
        .find(|(d, _)| *d <= dof.max(1))
        .map_or(f64::INFINITY, |&(_, t)| t)
}

/// The seed of pass `k` of a reference seeded with `seed` (pass 0 uses `seed` itself).
pub fn pass_seed(seed: u64, k: u32) -> u64 {
    if k == 0 {
        seed
    } else {
        mix64(seed ^ mix64(u64::from(k).wrapping_mul(0x9E37_79B9_7F4A_7C15)))
    }
}

/// How `min_spp` splits into passes: `(passes, [columns, rows] of one pass's strata)`. A pass has
/// the largest sample count that leaves at least [`MIN_PASSES`] passes (every sample its own pass
/// below that) and stratifies within [`MAX_SPP_SIDE`] per side, as squarely as it divides.
pub fn pass_layout(min_spp: u32) -> (u32, [u32; 2]) {
    (1..=(min_spp / MIN_PASSES).max(1))
        .rev()
        .filter(|d| min_spp.is_multiple_of(*d))
        .map(|d| (min_spp / d, square_strata(d)))
        .find(|(_, [_, m])| *m <= MAX_SPP_SIDE)
        .unwrap_or((min_spp, [1, 1]))
}

/// One pixel's running statistics of its independent pass means (Welford's update, in f64): the
/// mean, its standard error and its interval on the display. The adaptive reference and the
/// viewer's progressive reference keep one per pixel.
#[derive(Clone, Copy, Debug, Default)]
pub struct PassStats {
    n: u32,
    mean: [f64; 4],
    m2: [f64; 4],
}

impl PassStats {
    /// Adds one pass's mean (linear RGBA).
    pub fn add(&mut self, x: [f32; 4]) {
        self.n += 1;
        let n = f64::from(self.n);
        for c in 0..4 {
            let x = f64::from(x[c]);
            let d = x - self.mean[c];
            self.mean[c] += d / n;
            self.m2[c] += d * (x - self.mean[c]);
        }
    }

    /// The passes added so far.
    pub fn passes(&self) -> u32 {
        self.n
    }

    /// The mean of the passes (linear RGBA; zero before the first).
    pub fn mean(&self) -> [f32; 4] {
        self.mean.map(|m| m as f32)
    }

    /// The standard error of [`PassStats::mean`] per channel ([`pass_std_error`]).
    pub fn std_error(&self) -> [f64; 4] {
        self.m2.map(|m2| pass_std_error(m2, self.n))
    }

    /// The largest distance over R, G, B between the displayed mean and the displayed ends of the
    /// 95 % interval ([`display_half_width`]); infinite below two passes.
    pub fn display_half_width(&self, srgb: bool) -> f64 {
        if self.n < 2 {
            return f64::INFINITY;
        }
        let se = self.std_error();
        display_half_width(
            [self.mean[0], self.mean[1], self.mean[2]],
            [se[0], se[1], se[2]],
            self.n,
            srgb,
        )
    }
}

/// A reference that converges while it is shown: each pixel of a `width` x `height` frame keeps
/// the [`PassStats`] of the independent passes added to it, so that a viewer draws their mean and
/// reports the share of pixels whose interval on the display is within the plan's tolerance (the
/// rule [`render_reference_adaptive`] stops refining a pixel by).
#[derive(Clone, Debug, Default)]
pub struct ProgressiveReference {
    width: u32,
    height: u32,
    tolerance: f64,
    srgb_display: bool,
    pixels: Vec<PassStats>,
}

impl ProgressiveReference {
    /// An empty reference of `width` x `height` pixels judged by `plan`'s tolerance and display
    /// encoding.
    pub fn new(width: u32, height: u32, plan: &ReferencePlan) -> Self {
        ProgressiveReference {
            width,
            height,
            tolerance: plan.tolerance,
            srgb_display: plan.srgb_display,
            pixels: vec![PassStats::default(); width as usize * height as usize],
        }
    }

    /// Whether this reference is `width` x `height` pixels judged as `plan` says.
    pub fn fits(&self, width: u32, height: u32, plan: &ReferencePlan) -> bool {
        (self.width, self.height, self.tolerance, self.srgb_display)
            == (width, height, plan.tolerance, plan.srgb_display)
    }

    /// Adds the pixels of `rect` (`[x0, y0, x1, y1]`) of one pass (each pixel the mean of its
    /// strata, linear RGBA), a frame of this reference's size.
    ///
    /// # Panics
    /// If `rect` reaches outside the frame or `pass` is of another size (a programming error).
    pub fn add(&mut self, pass: &Frame, rect: [u32; 4]) {
        assert_eq!(pass.color.len(), self.pixels.len(), "pass of another size");
        for k in self.indices(rect) {
            self.pixels[k].add(pass.color[k]);
        }
    }

    /// Writes the mean of every pixel of `rect` into `color` (a frame's colour of this size).
    pub fn mean_into(&self, rect: [u32; 4], color: &mut [[f32; 4]]) {
        for k in self.indices(rect) {
            color[k] = self.pixels[k].mean();
        }
    }

    /// The share of the pixels of `rect` whose 95 % interval on the display is within the
    /// tolerance ([`PassStats::display_half_width`]); 0 for an empty `rect`.
    pub fn share_within(&self, rect: [u32; 4]) -> f64 {
        use rayon::prelude::*;
        let [x0, y0, x1, y1] = rect;
        let within =
            |k: usize| self.pixels[k].display_half_width(self.srgb_display) <= self.tolerance;
        // Rows in parallel: each pixel's interval takes a few sRGB encodes.
        let inside: usize = (y0..y1)
            .into_par_iter()
            .map(|y| {
                let row = y as usize * self.width as usize;
                (x0..x1).filter(|&x| within(row + x as usize)).count()
            })
            .sum();
        let n = u64::from(x1.saturating_sub(x0)) * u64::from(y1.saturating_sub(y0));
        if n == 0 {
            0.0
        } else {
            inside as f64 / n as f64
        }
    }

    /// The indices of `rect`'s pixels, row by row.
    fn indices(&self, rect: [u32; 4]) -> impl Iterator<Item = usize> {
        let [x0, y0, x1, y1] = rect;
        assert!(
            x1 <= self.width && y1 <= self.height,
            "rect outside the frame"
        );
        let w = self.width as usize;
        (y0..y1).flat_map(move |y| (x0..x1).map(move |x| y as usize * w + x as usize))
    }
}

/// The standard error of the mean of `n` independent pass means whose squared deviations from
/// their mean sum to `m2` (the passes' sample deviation over `sqrt(n)`); infinite below two
/// passes. A negative `m2` (rounding in a caller's `sum x^2 - n mean^2`) counts as 0.
pub fn pass_std_error(m2: f64, n: u32) -> f64 {
    if n < 2 {
        return f64::INFINITY;
    }
    let n = f64::from(n);
    (m2.max(0.0) / (n - 1.0) / n).sqrt()
}

/// The largest distance over R, G, B between the displayed value of `mean` (linear) and the
/// displayed ends of its 95 % interval, `mean +- t std_error` with Student's `t` for `n - 1`
/// degrees of freedom ([`t_975`]), in display units (1 is full scale: half an 8-bit step is
/// `0.5 / 255`). `n` is the number of independent passes the mean and its standard error come
/// from; below two the width is infinite. A converging reference stops refining a pixel once
/// this is within its tolerance; the viewer reports the share of pixels for which it is.
pub fn display_half_width(mean: [f64; 3], std_error: [f64; 3], n: u32, srgb: bool) -> f64 {
    if n < 2 {
        return f64::INFINITY;
    }
    let t = t_975(n - 1);
    (0..3)
        .map(|c| {
            let (m, h) = (mean[c], t * std_error[c]);
            let d = display(m, srgb);
            (display(m + h, srgb) - d).max(d - display(m - h, srgb))
        })
        .fold(0.0, f64::max)
}

/// `plan` checked against its ranges.
fn check_plan(plan: &ReferencePlan) -> Result<(), RasterError> {
    let max_min = MAX_SPP_SIDE * MAX_SPP_SIDE;
    let valid = (1..=max_min).contains(&plan.min_spp)
        && (plan.min_spp..=MAX_ADAPTIVE_SPP).contains(&plan.max_spp)
        && plan.tolerance >= 0.0
        && plan.tolerance.is_finite();
    if !valid {
        return Err(RasterError::InvalidReferencePlan {
            min_spp: plan.min_spp,
            min_max: max_min,
            max_spp: plan.max_spp,
            max_max: MAX_ADAPTIVE_SPP,
            tolerance: plan.tolerance,
        });
    }
    Ok(())
}

/// The estimate the passes' statistics make: each pixel's mean, standard error, interval
/// half-width on the display, samples and whether it converged.
fn estimate(
    settings: &RenderSettings,
    stats: &[PassStats],
    mut depth: Vec<f32>,
    plan: &ReferencePlan,
    per_pass: u32,
    interrupted: bool,
    exact: Option<&ExactImage>,
) -> ReferenceEstimate {
    // An interrupted round leaves its pixels with more passes than the others: each is still the
    // mean of whole passes, and its own statistics say how far it got.
    let half: Vec<f64> = stats
        .iter()
        .map(|s| s.display_half_width(plan.srgb_display))
        .collect();
    let mut half = half;
    let mut converged: Vec<bool> = half.iter().map(|&h| h <= plan.tolerance).collect();
    let mut color: Vec<[f32; 4]> = stats.iter().map(|s| s.mean.map(|m| m as f32)).collect();
    let mut std_error: Vec<[f32; 4]> = stats
        .iter()
        .map(|s| s.std_error().map(|e| e as f32))
        .collect();
    let mut spp: Vec<u32> = stats.iter().map(|s| s.n * per_pass).collect();
    let pixels = stats.len();
    let mut is_exact = vec![false; pixels];
    if let Some(ex) = exact {
        for i in (0..pixels).filter(|&i| ex.exact[i]) {
            let (c, b) = (ex.color[i], ex.bound[i]);
            color[i] = c;
            std_error[i] = [0.0; 4];
            spp[i] = 0;
            depth[i] = ex.depth[i];
            half[i] = (0..3)
                .map(|k| {
                    let (m, h) = (f64::from(c[k]), f64::from(b[k]));
                    let d = display(m, plan.srgb_display);
                    (display(m + h, plan.srgb_display) - d)
                        .max(d - display(m - h, plan.srgb_display))
                })
                .fold(0.0, f64::max);
            converged[i] = true;
            is_exact[i] = true;
        }
    }
    let frame = Frame {
        width: settings.width,
        height: settings.height,
        target: crate::settings::ColorTarget::Float,
        // Every pixel has at least one pass: a stop before the first is an error
        // (`render_reference_adaptive`).
        color,
        color8: Vec::new(),
        texels_read: Vec::new(),
        depth,
        footprints: Vec::new(),
        cleared: Default::default(),
    };
    ReferenceEstimate {
        frame,
        std_error,
        display_half_width: half.iter().map(|&h| h as f32).collect(),
        spp,
        exact: is_exact,
        converged,
        interrupted,
        plan: *plan,
    }
}

/// Render a reference of `draws` that converges as `plan` says (see the module docs).
///
/// `progress`, if given, is called from worker threads as pixels finish. `stop`, if given, is
/// read between pixel rows: once it is set, no further row starts and the estimate so far is
/// returned, marked interrupted (each pixel the mean of the whole passes it got).
///
/// # Errors
/// As [`crate::render`]; [`RasterError::InvalidReferencePlan`] for a plan outside its ranges; a
/// stop before the first pass completes is [`RasterError::Interrupted`].
pub fn render_reference_adaptive(
    settings: &RenderSettings,
    draws: &[DrawCall],
    plan: &ReferencePlan,
    progress: Option<&(dyn Fn(&ReferenceStatus) + Sync)>,
    stop: Option<&AtomicBool>,
) -> Result<ReferenceEstimate, RasterError> {
    check_plan(plan)?;
    let (first_passes, strata) = pass_layout(plan.min_spp);
    let per_pass = strata[0] * strata[1];
    let max_passes = plan.max_spp / per_pass;
    let pixels = settings.width as usize * settings.height as usize;
    let mut stats = vec![PassStats::default(); pixels];
    let mut depth = vec![f32::INFINITY; pixels];
    let mut interrupted = false;
    let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let exact = exact_pixels(settings, draws, plan, progress)?;
    with_passes(settings, draws, strata, |pass| {
        // The pixels this round refines, as indices and (after round 0) as the passes' mask;
        // every other pixel has converged or is exact.
        let mut indices: Vec<usize> = (0..pixels)
            .filter(|&i| exact.as_ref().is_none_or(|e| !e.exact[i]))
            .collect();
        if indices.is_empty() {
            return Ok(());
        }
        let mut active = exact.is_some().then(|| mask_of(&indices, pixels));
        let mut done_passes = 0u32;
        let mut round = 0u32;
        let mut add = first_passes;
        loop {
            let active_count = indices.len() as u64;
            let converged_before = 1.0 - active_count as f64 / pixels as f64;
            for k in 0..add {
                if stopped() {
                    interrupted = true;
                    break;
                }
                let status = |done: u64, _total: u64| {
                    if let Some(p) = progress {
                        p(&ReferenceStatus {
                            round,
                            spp: (done_passes + add) * per_pass,
                            active: active_count,
                            converged: converged_before,
                            done: u64::from(k) * active_count
                                + done * active_count / pixels.max(1) as u64,
                            total: u64::from(add) * active_count,
                        });
                    }
                };
                let (frame, partial) = pass(
                    pass_seed(plan.seed, done_passes + k),
                    active.as_deref(),
                    Some(&status),
                    stop,
                )?;
                // A stopped pass rendered whole pixel rows: those pixels take it, the others
                // keep the passes they had.
                for &i in &indices {
                    if partial.as_ref().is_none_or(|rendered| rendered[i]) {
                        stats[i].add(frame.color[i]);
                        depth[i] = depth[i].min(frame.depth[i]);
                    }
                }
                if partial.is_some() {
                    interrupted = true;
                    break;
                }
            }
            // Round 0 gives every pixel the first pass: a pixel without one was stopped before
            // it, and the estimate has nothing to show there.
            if interrupted && round == 0 && indices.iter().any(|&i| stats[i].n == 0) {
                return Err(RasterError::Interrupted);
            }
            if interrupted {
                break;
            }
            done_passes += add;
            indices.retain(|&i| stats[i].display_half_width(plan.srgb_display) > plan.tolerance);
            add = done_passes.min(max_passes.saturating_sub(done_passes));
            if indices.is_empty() || add == 0 {
                break;
            }
            active = Some(mask_of(&indices, pixels));
            round += 1;
        }
        Ok(())
    })?;
    Ok(estimate(
        settings,
        &stats,
        depth,
        plan,
        per_pass,
        interrupted,
        exact.as_ref(),
    ))
}

/// The exact pixels of the plan's image where the plan asks for them, reported to `progress` as
/// round 0.
fn exact_pixels(
    settings: &RenderSettings,
    draws: &[DrawCall],
    plan: &ReferencePlan,
    progress: Option<&(dyn Fn(&ReferenceStatus) + Sync)>,
) -> Result<Option<ExactImage>, RasterError> {
    if !plan.exact {
        return Ok(None);
    }
    let status = |done: u64, total: u64| {
        if let Some(p) = progress {
            p(&ReferenceStatus {
                round: 0,
                spp: 0,
                active: total,
                converged: 0.0,
                done,
                total,
            });
        }
    };
    Ok(Some(render_exact(settings, draws, Some(&status))?))
}

/// A mask of `pixels` pixels, true at `indices`.
fn mask_of(indices: &[usize], pixels: usize) -> Vec<bool> {
    let mut mask = vec![false; pixels];
    for &i in indices {
        mask[i] = true;
    }
    mask
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pass_layouts() {
        assert_eq!(pass_layout(256), (8, [4, 8]));
        assert_eq!(pass_layout(1024), (8, [8, 16]));
        assert_eq!(pass_layout(4096), (8, [16, 32]));
        assert_eq!(pass_layout(7), (7, [1, 1]));
        assert_eq!(pass_layout(1), (1, [1, 1]));
        assert_eq!(pass_layout(24), (8, [1, 3]));
        // 536 = 8 x 67: a pass of 67 samples cannot stratify within 64 per side.
        assert_eq!(pass_layout(536), (67, [2, 4]));
        for spp in 1..=4096 {
            let (k, [n, m]) = pass_layout(spp);
            assert_eq!(k * n * m, spp, "{spp}");
            assert!(
                k >= MIN_PASSES.min(spp) && n <= m && m <= MAX_SPP_SIDE,
                "{spp}"
            );
        }
    }

    #[test]
    fn welford_matches_the_two_pass_formulas() {
        let xs = [0.25f32, 0.5, 1.75, 0.0, 3.0];
        let mut s = PassStats::default();
        for x in xs {
            s.add([x; 4]);
        }
        let n = xs.len() as f64;
        let mean = xs.iter().map(|&x| f64::from(x)).sum::<f64>() / n;
        let var = xs
            .iter()
            .map(|&x| (f64::from(x) - mean).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        assert!((s.mean[0] - mean).abs() < 1e-12);
        assert!((s.std_error()[0] - (var / n).sqrt()).abs() < 1e-12);
        // From a sum of squares: the same error.
        let squares: f64 = xs.iter().map(|&x| f64::from(x).powi(2)).sum();
        let se = pass_std_error(squares - n * mean * mean, xs.len() as u32);
        assert!((se - (var / n).sqrt()).abs() < 1e-12);
        assert!(pass_std_error(0.0, 1).is_infinite());
        assert_eq!(pass_std_error(-1e-18, 3), 0.0);
    }

    /// A progressive reference holds each pixel's passes apart: the rect a pass covers gets its
    /// mean, and a pixel is within the tolerance when its passes agree.
    #[test]
    fn a_progressive_reference_adds_passes_per_rect() {
        let settings = RenderSettings {
            width: 4,
            height: 2,
            ..RenderSettings::default()
        };
        let plan = ReferencePlan {
            srgb_display: false,
            ..ReferencePlan::default()
        };
        let mut r = ProgressiveReference::new(4, 2, &plan);
        assert!(r.fits(4, 2, &plan) && !r.fits(2, 4, &plan));
        let mut pass = Frame::new(&settings);
        // Three passes: the left half constant, the right half spread by 0.1.
        for v in [0.4f32, 0.5, 0.6] {
            for (k, c) in pass.color.iter_mut().enumerate() {
                *c = if k % 4 < 2 { [0.25; 4] } else { [v; 4] };
            }
            r.add(&pass, [0, 0, 4, 2]);
        }
        // A fourth pass over the top-left pixel only.
        pass.color[0] = [0.25; 4];
        r.add(&pass, [0, 0, 1, 1]);
        let mut color = vec![[0.0; 4]; 8];
        r.mean_into([0, 0, 4, 2], &mut color);
        assert_eq!(color[0], [0.25; 4]);
        assert!((color[3][0] - 0.5).abs() < 1e-6);
        assert_eq!(r.share_within([0, 0, 2, 2]), 1.0);
        assert_eq!(r.share_within([2, 0, 4, 2]), 0.0);
        assert_eq!(r.share_within([0, 0, 4, 2]), 0.5);
        assert_eq!(r.share_within([1, 1, 1, 2]), 0.0, "an empty rect");
    }

    #[test]
    fn the_display_clips_and_encodes() {
        // An interval wholly above 1 shows as 1 at both ends: width zero.
        let mut s = PassStats::default();
        for x in [5.0f32, 9.0, 7.0] {
            s.add([x, x, x, 1.0]);
        }
        assert_eq!(s.display_half_width(true), 0.0);
        // Linear display: the half-width is t * s / sqrt(n) while the interval stays in [0, 1].
        let mut s = PassStats::default();
        for x in [0.4f32, 0.5, 0.6] {
            s.add([x, x, x, 1.0]);
        }
        let expected = t_975(2) * 0.1 / 3f64.sqrt();
        assert!((s.display_half_width(false) - expected).abs() < 1e-6);
        // sRGB is steeper than linear below mid-grey.
        assert!(s.display_half_width(true) > 0.0);
        let mut one = PassStats::default();
        one.add([0.5; 4]);
        assert!(one.display_half_width(true).is_infinite());
    }

    #[test]
    fn t_quantiles() {
        assert_eq!(t_975(1), 12.706);
        assert_eq!(t_975(7), 2.365);
        assert_eq!(t_975(11), 2.228);
        assert_eq!(t_975(1 << 20), 1.962);
        assert!(t_975(u32::MAX) == 1.96);
        for d in 1..2000 {
            assert!(t_975(d) >= t_975(d + 1));
        }
    }

    #[test]
    fn pass_seeds_differ() {
        let seeds: std::collections::HashSet<u64> = (0..1000).map(|k| pass_seed(7, k)).collect();
        assert_eq!(seeds.len(), 1000);
        assert_eq!(pass_seed(7, 0), 7);
    }
}
