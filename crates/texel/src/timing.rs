//! Frame times as `texel bench` and `texel compare` measure them.
//!
//! What is timed: one call of [`draw_into`] — setting up, clipping, binning, rasterizing,
//! sampling and shading every triangle into a frame cleared beforehand — with the textures, their
//! pyramids and any ripmap or summed-area table built beforehand. The clear ([`Frame::reset`], a
//! fill of the reused buffers) is timed apart. No file I/O, no encoding.

use std::time::{Duration, Instant};

use texel_raster::{draw_into, DrawCall, Frame, RasterError, RenderSettings};

/// Times of one filter's frames in milliseconds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameTimes {
    /// The draw of each timed frame ([`draw_into`] after an untimed clear).
    pub draw_ms: Vec<f64>,
    /// The clear ([`Frame::reset`]) before each timed frame.
    pub clear_ms: Vec<f64>,
    /// Whether the timed draws streamed their tiles out ([`Frame::draw_streams`]).
    pub streamed: bool,
}

/// Shortest warm-up when any is asked for: fast frames run measurably slower while they are all
/// the machine has run (decisions.md), so warm-up lasts at least this long.
pub const MIN_WARMUP: Duration = Duration::from_millis(200);

/// Most warm-up frames [`MIN_WARMUP`] can add (a bound for very fast frames).
const MAX_WARMUP_FRAMES: u32 = 10_000;

/// Untimed warm-up: call `step`, which does `per_call` units of work (frames, passes), until at
/// least `warmup` units are done and, unless `warmup` is 0, until `min_warmup` has passed or
/// ten thousand units are done.
///
/// # Errors
/// The first error of `step`.
pub fn warm_up<E>(
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
pub fn time_frames(
    settings: &RenderSettings,
    draws: &[DrawCall],
    warmup: u32,
    min_warmup: Duration,
    frames: u32,
) -> Result<FrameTimes, RasterError> {
    let mut frame = Frame::new(settings);
    let mut times = FrameTimes::default();
    warm_up(warmup, min_warmup, 1, || {
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

#[cfg(test)]
mod tests {
    use super::median;

    #[test]
    fn medians() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(median(&mut [7.0]), 7.0);
        assert_eq!(median(&mut []), 0.0);
    }
}
