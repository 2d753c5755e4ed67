//! Frame times as `texel bench` and `texel compare` measure them, and the bench's rows
//! ([`time_filters`]).
//!
//! What is timed: one call of [`draw_into`] — setting up, clipping, binning, rasterizing,
//! sampling and shading every triangle into a frame cleared beforehand — with the textures, their
//! pyramids and any ripmap or summed-area table built beforehand. The clear ([`Frame::reset`], a
//! fill of the reused buffers) is timed apart. No file I/O, no encoding.

use std::time::{Duration, Instant};

use texel_prepare::{Error, MemoryBudget, PreparedScene};
use texel_raster::{draw_into, ColorTarget, DrawCall, Frame, RasterError, RenderSettings};
use texel_texture::Filter;

/// Times of one filter's frames in milliseconds.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct FrameTimes {
    /// The draw of each timed frame ([`draw_into`] after an untimed clear).
    pub draw_ms: Vec<f64>,
    /// The clear ([`Frame::reset`]) before each timed frame.
    pub clear_ms: Vec<f64>,
    /// Whether the timed draws streamed their tiles out ([`Frame::draw_streams`]).
    pub streamed: bool,
}

/// Shortest warm-up when any is asked for: fast frames run measurably slower while they are all
/// the machine has run (decisions.md), so warm-up lasts at least this long.
pub(crate) const MIN_WARMUP: Duration = Duration::from_millis(200);

/// Most warm-up frames [`MIN_WARMUP`] can add (a bound for very fast frames).
const MAX_WARMUP_FRAMES: u32 = 10_000;

/// Untimed warm-up: call `step`, which does `per_call` units of work (frames, passes), until at
/// least `warmup` units are done and, unless `warmup` is 0, until 200 ms have passed or ten
/// thousand units are done (fast frames run measurably slower while they are all the machine has
/// run).
///
/// # Errors
/// The first error of `step`.
pub fn warm_up<E>(
    warmup: u32,
    per_call: u32,
    step: impl FnMut() -> Result<(), E>,
) -> Result<(), E> {
    warm_up_for(warmup, MIN_WARMUP, per_call, step)
}

/// [`warm_up`] for at least `min_warmup` instead of [`MIN_WARMUP`].
fn warm_up_for<E>(
    warmup: u32,
    min_warmup: Duration,
    per_call: u32,
    mut step: impl FnMut() -> Result<(), E>,
) -> Result<(), E> {
    let start = Instant::now();
    let mut k = 0u32;
    while k < warmup || (warmup > 0 && k < MAX_WARMUP_FRAMES && start.elapsed() < min_warmup) {
        step()?;
        k = k.saturating_add(per_call.max(1));
    }
    Ok(())
}

/// Draw untimed frames (at least `warmup`, and while `warmup > 0` until `min_warmup` has passed),
/// then `frames` timed ones into one reused frame, clearing it before each; the timed frames'
/// clear and draw times in milliseconds.
///
/// # Errors
/// The draw's errors ([`draw_into`]).
pub(crate) fn time_frames(
    settings: &RenderSettings,
    draws: &[DrawCall],
    warmup: u32,
    min_warmup: Duration,
    frames: u32,
) -> Result<FrameTimes, RasterError> {
    let mut frame = Frame::new(settings);
    let mut times = FrameTimes::default();
    warm_up_for(warmup, min_warmup, 1, || {
        frame.reset(settings);
        draw_into(settings, draws, &mut frame)?;
        std::hint::black_box(&frame);
        Ok::<_, RasterError>(())
    })?;
    for _ in 0..frames {
        let t0 = Instant::now();
        frame.reset(settings);
        let t1 = Instant::now();
        times.streamed = frame.draw_streams();
        draw_into(settings, draws, &mut frame)?;
        let t2 = Instant::now();
        std::hint::black_box(&frame);
        times.clear_ms.push((t1 - t0).as_secs_f64() * 1e3);
        times.draw_ms.push((t2 - t1).as_secs_f64() * 1e3);
    }
    Ok(times)
}

/// Median of a list (sorted in place); 0 for an empty one.
pub fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n {
        0 => 0.0,
        _ if n % 2 == 1 => v[n / 2],
        _ => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// One filter's frame times as `texel bench` reports them, in milliseconds.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterTiming {
    /// The filter's name (or the GPU row's label).
    pub filter: &'static str,
    /// Median of the timed frames.
    pub median_ms: f64,
    /// Fastest timed frame.
    pub min_ms: f64,
    /// Slowest timed frame.
    pub max_ms: f64,
    /// Median of the second series: the clears before the timed frames on the CPU, a render
    /// pass's device time on a GPU (0 when there is none).
    pub second_ms: f64,
    /// Whether the timed frames were drawn in scratch and streamed out
    /// ([`Frame::draw_streams`]).
    pub streamed: bool,
}

impl FilterTiming {
    /// The row of `filter`'s timed frames `frames_ms`: their median, fastest and slowest, with
    /// the median of `second_ms` (0 for none). All 0 without frames.
    pub fn of(
        filter: &'static str,
        mut frames_ms: Vec<f64>,
        mut second_ms: Vec<f64>,
        streamed: bool,
    ) -> Self {
        let min_ms = frames_ms.iter().copied().reduce(f64::min).unwrap_or(0.0);
        let max_ms = frames_ms.iter().copied().reduce(f64::max).unwrap_or(0.0);
        FilterTiming {
            filter,
            median_ms: median(&mut frames_ms),
            min_ms,
            max_ms,
            second_ms: median(&mut second_ms),
            streamed,
        }
    }
}

/// How [`time_filters`] times each filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BenchPlan {
    /// Untimed frames first (and while more than 0, at least 200 ms of them).
    pub warmup: u32,
    /// Timed frames.
    pub frames: u32,
    /// Draw into a float target instead of the scene's 8-bit one.
    pub float_target: bool,
    /// Worker threads (`None`: rayon's default, every core).
    pub threads: Option<usize>,
}

/// Each filter's frame times on the CPU, as `texel bench` measures them: per filter its
/// samplers and tables built (and charged to `budget`), then its warm-up and timed frames
/// (each cleared, then drawn into one reused frame) on a pool of `plan.threads` built once.
///
/// # Errors
/// The plan's errors ([`PreparedScene::plan`]: the memory budget), the draw's, and a thread pool
/// that cannot be built.
pub fn time_filters(
    scene: &PreparedScene,
    filters: &[Filter],
    plan: &BenchPlan,
    budget: &mut MemoryBudget,
) -> Result<Vec<FilterTiming>, Error> {
    texel_raster::on_threads(plan.threads, || {
        filters
            .iter()
            .map(|&filter| {
                let frame = scene.plan(Some(filter), budget)?;
                let draws = frame.draws();
                let mut settings = frame.settings();
                if plan.float_target {
                    settings.target = ColorTarget::Float;
                }
                let times = time_frames(&settings, &draws, plan.warmup, MIN_WARMUP, plan.frames)?;
                Ok(FilterTiming::of(
                    filter.name(),
                    times.draw_ms,
                    times.clear_ms,
                    times.streamed,
                ))
            })
            .collect()
    })?
}

#[cfg(test)]
mod tests {
    use super::*;
    use texel_prepare::SceneOptions;
    use texel_scene::Scene;

    #[test]
    fn medians() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(median(&mut [7.0]), 7.0);
        assert_eq!(median(&mut []), 0.0);
    }

    #[test]
    fn a_row_holds_the_median_and_the_extremes() {
        let row = FilterTiming::of("x", vec![4.0, 1.0, 9.0, 2.0], vec![0.5, 0.25, 1.0], true);
        assert_eq!((row.median_ms, row.min_ms, row.max_ms), (3.0, 1.0, 9.0));
        assert_eq!((row.second_ms, row.streamed), (0.5, true));
        let none = FilterTiming::of("y", Vec::new(), Vec::new(), false);
        assert_eq!(
            (none.median_ms, none.min_ms, none.max_ms, none.second_ms),
            (0.0, 0.0, 0.0, 0.0)
        );
    }

    /// One row per filter, in order, each from the frames asked for; a budget too small for the
    /// summed-area table fails before any frame.
    #[test]
    fn the_bench_times_every_filter() {
        let scene = Scene::load("builtin:ground").unwrap();
        let options = SceneOptions {
            size: Some((32, 18)),
            ..SceneOptions::default()
        };
        let mut budget = MemoryBudget::limit_or_default(None);
        let prepared = PreparedScene::new(scene, &options, &mut budget).unwrap();
        let plan = BenchPlan {
            warmup: 0,
            frames: 3,
            float_target: true,
            threads: Some(1),
        };
        let filters = [Filter::Nearest, Filter::Aniso16];
        let rows = time_filters(&prepared, &filters, &plan, &mut budget).unwrap();
        assert_eq!(rows.len(), 2);
        for (row, f) in rows.iter().zip(filters) {
            assert_eq!(row.filter, f.name());
            assert!(
                row.min_ms <= row.median_ms && row.median_ms <= row.max_ms,
                "{row:?}"
            );
            assert!(row.min_ms > 0.0 && !row.streamed, "{row:?}");
        }
        let mut tight = MemoryBudget::new(1, "a one-byte limit");
        let err = time_filters(&prepared, &[Filter::Sat], &plan, &mut tight).unwrap_err();
        assert!(matches!(err, Error::OverBudget { .. }), "{err}");
    }
}
