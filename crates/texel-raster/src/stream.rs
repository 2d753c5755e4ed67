//! When a frame's buffers are written with non-temporal ("streaming") stores.
//!
//! A plain store to a line that is not in the cache first reads the line from memory (to own it),
//! then writes it back when it is evicted: a frame larger than the cache costs its size twice
//! in memory traffic on every draw, and pushes the textures out of the cache on the way. A GPU
//! does not read a cleared target: it knows the clear (fast-clear state) and stores whole tiles.
//! texel does the same for a frame that holds its clear ([`crate::Frame::reset`]) and is larger
//! than the last-level cache: each tile some triangle (or the environment background)
//! reaches is drawn in per-thread scratch filled with the clear, then copied out with
//! non-temporal stores ([`texel_texture::engine::dispatch::stream_copy`]); a tile nothing reaches keeps
//! the clear the frame already holds. `reset` writes such a frame with non-temporal stores too,
//! so the draw does not first write back the clear's dirty lines. Images are bit for bit the
//! same either way (`tests/streaming.rs`); only the memory traffic differs (docs/decisions.md,
//! "Frames larger than the last-level cache are streamed like a fast-cleared target").

use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::OnceLock;

/// How draws write frames: whether [`crate::Frame::reset`] and a draw into a frame that holds
/// its clear use non-temporal stores. Process-wide ([`set_streaming`]); images do not depend on it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Streaming {
    /// Stream frames larger than the last-level cache ([`last_level_cache_bytes`]): frames that
    /// fit in the cache draw no faster streamed, larger ones do (figures in docs/decisions.md).
    #[default]
    #[cfg_attr(
        feature = "clap",
        value(help = "Stream frames larger than the last-level cache")
    )]
    Auto,
    /// Stream every frame (for measuring: a frame that fits the cache draws slower this way).
    #[cfg_attr(feature = "clap", value(help = "Stream every frame"))]
    Always,
    /// Never stream: tiles draw in place into the frame.
    #[cfg_attr(feature = "clap", value(help = "Draw every frame in place"))]
    Never,
}

impl Streaming {
    /// The policy's name, as reports and the command line write it: `auto`, `always`, `never`.
    pub fn name(self) -> &'static str {
        match self {
            Streaming::Auto => "auto",
            Streaming::Always => "always",
            Streaming::Never => "never",
        }
    }
}

/// The process-wide policy, as its index in `[Auto, Always, Never]`.
static POLICY: AtomicU8 = AtomicU8::new(0);

/// Set how later resets and draws write frames (for comparing the two ways in one process;
/// images do not depend on it).
pub fn set_streaming(policy: Streaming) {
    POLICY.store(policy as u8, Ordering::Relaxed);
}

/// The policy [`set_streaming`] set last ([`Streaming::Auto`] unless set).
pub fn streaming() -> Streaming {
    match POLICY.load(Ordering::Relaxed) {
        1 => Streaming::Always,
        2 => Streaming::Never,
        _ => Streaming::Auto,
    }
}

/// Bytes of the largest CPU cache Linux reports for CPU 0
/// (`/sys/devices/system/cpu/cpu0/cache/index*/size`), read once; 32 MiB where none is reported
/// (another OS, a container that hides `/sys`).
pub fn last_level_cache_bytes() -> usize {
    static LLC: OnceLock<usize> = OnceLock::new();
    *LLC.get_or_init(|| {
        let sizes = (0..8).filter_map(|i| {
            let path = format!("/sys/devices/system/cpu/cpu0/cache/index{i}/size");
            parse_cache_size(std::fs::read_to_string(path).ok()?.trim())
        });
        sizes.max().unwrap_or(32 << 20)
    })
}

/// A sysfs cache size (`"32768K"`, `"1M"`, `"512"`) in bytes; `None` if it is not one.
fn parse_cache_size(s: &str) -> Option<usize> {
    let (digits, unit) = match s.char_indices().find(|(_, c)| !c.is_ascii_digit()) {
        Some((k, _)) => s.split_at(k),
        None => (s, ""),
    };
    let n: usize = digits.parse().ok()?;
    let scale = match unit {
        "" => 1,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        _ => return None,
    };
    n.checked_mul(scale)
}

/// Whether a frame of `bytes` bytes (colour and depth) is written with non-temporal stores under
/// the current policy.
pub(crate) fn streams(bytes: usize) -> bool {
    match streaming() {
        Streaming::Auto => bytes > last_level_cache_bytes(),
        Streaming::Always => true,
        Streaming::Never => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cache_sizes_parse_as_sysfs_writes_them() {
        assert_eq!(parse_cache_size("32768K"), Some(32 << 20));
        assert_eq!(parse_cache_size("1M"), Some(1 << 20));
        assert_eq!(parse_cache_size("512"), Some(512));
        assert_eq!(parse_cache_size("2G"), Some(2 << 30));
        assert_eq!(parse_cache_size("K"), None);
        assert_eq!(parse_cache_size("12Q"), None);
        assert_eq!(parse_cache_size(""), None);
    }

    #[test]
    fn the_cache_size_is_plausible() {
        let b = last_level_cache_bytes();
        assert!((4 << 10..=4 << 30).contains(&b), "{b} bytes");
    }
}
