//! `--max-memory`: the bytes a command may hold at once, and the running account against it.
//!
//! Every allocation that grows with the input is counted before it is made: the meshes, each
//! texture while it loads (its file, decoded image, texels, pyramid and build scratch, through
//! [`texel_texture::Limits::max_bytes`] set to what is left), the frame and the encoded output,
//! and per command what it keeps besides (compare's images, mips' levels and chain). The figures
//! are upper bounds per pixel or texel, listed in [`FRAME_BYTES_PER_PIXEL`] and beside each use.
//! The default is half of this machine's memory (the smaller of `MemTotal` in `/proc/meminfo` and
//! the cgroup's `memory.max`), or [`FALLBACK_BYTES`] where neither can be read.

use anyhow::{bail, Result};

/// The budget when the machine's memory cannot be read: 8 GiB.
pub const FALLBACK_BYTES: u64 = 8 << 30;

/// What a rendered frame holds per pixel, at most: linear colour (16), depth (4), coverage (1),
/// texel counts (4), the 8-bit image (4), its RGBA bytes for the encoder (4) and the PNG (at most
/// about 4 plus headers) = 37, rounded up. (The CLI never captures footprints.)
pub const FRAME_BYTES_PER_PIXEL: u64 = 40;

/// A byte count from the command line: a whole number with an optional unit K, M, G, T (powers
/// of 1024; `KiB`, `MB`, ... are read the same way), at least 1 MiB.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ByteSize(pub u64);

impl std::str::FromStr for ByteSize {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let t = s.trim();
        let split = t.find(|c: char| !c.is_ascii_digit()).unwrap_or(t.len());
        let (num, unit) = t.split_at(split);
        let n: u64 = num
            .parse()
            .map_err(|_| format!("{s:?} is not a size (e.g. 512M, 4G or a number of bytes)"))?;
        let shift = match unit.trim().to_ascii_uppercase().as_str() {
            "" | "B" => 0,
            "K" | "KB" | "KIB" => 10,
            "M" | "MB" | "MIB" => 20,
            "G" | "GB" | "GIB" => 30,
            "T" | "TB" | "TIB" => 40,
            other => return Err(format!("{s:?}: unknown unit {other:?} (use K, M, G or T)")),
        };
        let bytes = n
            .checked_mul(1u64 << shift)
            .ok_or_else(|| format!("{s:?} is too large"))?;
        if bytes < 1 << 20 {
            return Err(format!("{s:?} is below the minimum of 1M"));
        }
        Ok(ByteSize(bytes))
    }
}

/// `bytes` in MiB with one decimal, for messages.
pub fn mib(bytes: u64) -> String {
    format!("{:.1} MiB", bytes as f64 / f64::from(1 << 20))
}

/// The machine's memory in bytes: the smaller of `MemTotal` and the cgroup v2 `memory.max`.
fn machine_memory() -> Option<u64> {
    let total = std::fs::read_to_string("/proc/meminfo").ok().and_then(|s| {
        s.lines()
            .find_map(|l| l.strip_prefix("MemTotal:"))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
            .map(|kb| kb * 1024)
    });
    let cgroup = std::fs::read_to_string("/sys/fs/cgroup/memory.max")
        .ok()
        .and_then(|s| s.trim().parse::<u64>().ok());
    match (total, cgroup) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// The running account of one command.
#[derive(Debug)]
pub struct Budget {
    limit: u64,
    used: u64,
    explicit: bool,
}

impl Budget {
    /// `--max-memory` if given, else half of the machine's memory.
    pub fn new(max_memory: Option<ByteSize>) -> Budget {
        match max_memory {
            Some(ByteSize(b)) => Budget {
                limit: b,
                used: 0,
                explicit: true,
            },
            None => Budget {
                limit: machine_memory().map_or(FALLBACK_BYTES, |m| m / 2),
                used: 0,
                explicit: false,
            },
        }
    }

    /// The `--max-memory` value this account was made from (`None`: the default).
    pub fn limit_arg(&self) -> Option<ByteSize> {
        self.explicit.then_some(ByteSize(self.limit))
    }

    /// Bytes not yet accounted for.
    pub fn remaining(&self) -> u64 {
        self.limit.saturating_sub(self.used)
    }

    /// The limit, for messages: `--max-memory 512.0 MiB` or `--max-memory's default ...`.
    pub fn describe(&self) -> String {
        if self.explicit {
            format!("--max-memory {}", mib(self.limit))
        } else {
            format!(
                "--max-memory's default {} (half of this machine's memory)",
                mib(self.limit)
            )
        }
    }

    /// Account for `bytes` that `what` will hold, or refuse with the figures.
    pub fn take(&mut self, what: &str, bytes: u64) -> Result<()> {
        let total = self.used.saturating_add(bytes);
        if total > self.limit && self.used == 0 {
            bail!(
                "{what} needs about {}, over {}: raise --max-memory or make the input smaller",
                mib(bytes),
                self.describe()
            );
        }
        if total > self.limit {
            bail!(
                "{what} needs about {} on top of {} already held, {} in all, over {}: raise --max-memory or make the input smaller",
                mib(bytes),
                mib(self.used),
                mib(total),
                self.describe()
            );
        }
        self.used = total;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse() {
        assert_eq!("512M".parse::<ByteSize>(), Ok(ByteSize(512 << 20)));
        assert_eq!("4GiB".parse::<ByteSize>(), Ok(ByteSize(4 << 30)));
        assert_eq!("2g".parse::<ByteSize>(), Ok(ByteSize(2 << 30)));
        assert_eq!("1048576".parse::<ByteSize>(), Ok(ByteSize(1 << 20)));
        assert!("1K".parse::<ByteSize>().is_err());
        assert!("4X".parse::<ByteSize>().is_err());
        assert!("99999999999T".parse::<ByteSize>().is_err());
        assert!("".parse::<ByteSize>().is_err());
    }

    #[test]
    fn account_refuses_with_figures() {
        let mut b = Budget::new(Some(ByteSize(10 << 20)));
        b.take("a", 6 << 20).unwrap();
        assert_eq!(b.remaining(), 4 << 20);
        let e = b.take("the frame", 5 << 20).unwrap_err().to_string();
        assert!(
            e.contains("the frame needs about 5.0 MiB on top of 6.0 MiB"),
            "{e}"
        );
        assert!(
            e.contains("11.0 MiB in all, over --max-memory 10.0 MiB"),
            "{e}"
        );
        assert_eq!(b.remaining(), 4 << 20);
    }
}
