//! A memory budget: the bytes a piece of work may hold at once, and the running account against it.
//!
//! Every allocation that grows with the input is charged before it is made ([`MemoryBudget::take`]):
//! [`crate::PreparedScene::new`] charges the meshes, one frame and each texture (the texture's own
//! [`texel_texture::Limits::max_bytes`] is set to what is left while it loads, so its file, decoded
//! image, texels and pyramid scratch are bounded too, then its pyramid is charged). The per-pixel and
//! per-element figures are upper bounds read off the code, listed with each constant.

use crate::Error;

/// What a rendered frame holds per pixel, at most: linear colour (16), depth (4), coverage (1),
/// texel counts (4), the 8-bit image (4), its RGBA bytes for the encoder (4) and the PNG (at most
/// about 4 plus headers) = 37, rounded up. (Footprint capture, 24 more, is a debug option the
/// scene path does not use.)
pub const FRAME_BYTES_PER_PIXEL: u64 = 40;

/// What a scene keeps per vertex, at most: the scene's position, uv, normal and colour (48 bytes)
/// and the rasterizer's [`texel_raster::Vertex`].
pub const VERTEX_BYTES: u64 = 48 + std::mem::size_of::<texel_raster::Vertex>() as u64;

/// What a scene keeps per triangle: its indices (12 bytes) and an allowance of 244 bytes for the
/// rasterizer's per-frame triangle set-up and bins.
pub const TRIANGLE_BYTES: u64 = 256;

/// The budget when the machine's memory cannot be read: 8 GiB.
pub const FALLBACK_BYTES: u64 = 8 << 30;

/// `bytes` in MiB with one decimal, for messages.
pub fn mib(bytes: u64) -> String {
    format!("{:.1} MiB", bytes as f64 / f64::from(1 << 20))
}

/// ` on top of X already held, Y in all` when `used > 0`, for [`Error::OverBudget`]'s message.
pub(crate) fn held(used: u64, bytes: u64) -> String {
    if used == 0 {
        String::new()
    } else {
        format!(
            " on top of {} already held, {} in all",
            mib(used),
            mib(used.saturating_add(bytes))
        )
    }
}

/// The machine's memory in bytes, where it can be read: the smaller of `MemTotal`
/// (`/proc/meminfo`) and the cgroup v2 limit (`/sys/fs/cgroup/memory.max`).
pub fn machine_memory() -> Option<u64> {
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

/// The running account of one piece of work against a limit.
#[derive(Clone, Debug)]
pub struct MemoryBudget {
    limit: u64,
    used: u64,
    name: String,
}

impl MemoryBudget {
    /// A budget of `limit` bytes; `name` says what set it, in errors (e.g. `--max-memory 4.0 GiB`).
    pub fn new(limit: u64, name: impl Into<String>) -> Self {
        MemoryBudget {
            limit,
            used: 0,
            name: name.into(),
        }
    }

    /// Half of [`machine_memory`] (or [`FALLBACK_BYTES`] where it cannot be read).
    pub fn half_of_machine() -> Self {
        let limit = machine_memory().map_or(FALLBACK_BYTES, |m| m / 2);
        Self::new(
            limit,
            format!(
                "the memory limit of {} (half of this machine's memory)",
                mib(limit)
            ),
        )
    }

    /// The limit in bytes.
    pub fn limit(&self) -> u64 {
        self.limit
    }

    /// Bytes not yet accounted for.
    pub fn remaining(&self) -> u64 {
        self.limit.saturating_sub(self.used)
    }

    /// How the limit is described in errors.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Account for `bytes` that `what` will hold, or refuse (the account unchanged).
    ///
    /// # Errors
    /// [`Error::OverBudget`] with the figures.
    pub fn take(&mut self, what: &str, bytes: u64) -> Result<(), Error> {
        let total = self.used.saturating_add(bytes);
        if total > self.limit {
            return Err(Error::OverBudget {
                what: what.to_string(),
                bytes,
                used: self.used,
                limit: self.name.clone(),
            });
        }
        self.used = total;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn account_refuses_with_figures() {
        let mut b = MemoryBudget::new(10 << 20, "--max-memory 10.0 MiB");
        b.take("a", 6 << 20).unwrap();
        assert_eq!(b.remaining(), 4 << 20);
        let e = b.take("the frame", 5 << 20).unwrap_err().to_string();
        assert!(e.contains("the frame needs about 5.0 MiB on top of 6.0 MiB already held, 11.0 MiB in all, over --max-memory 10.0 MiB"), "{e}");
        assert_eq!(b.remaining(), 4 << 20);
        let e = MemoryBudget::new(1 << 20, "X")
            .take("y", 2 << 20)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("y needs about 2.0 MiB, over X: raise"), "{e}");
    }
}
