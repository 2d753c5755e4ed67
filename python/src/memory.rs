//! The memory budget of a call: every allocation that grows with the input is charged before it is
//! made, against `max_memory=` bytes when given, else the process's default
//! ([`MemoryBudget::process_default`]: the smallest of half the machine's memory, the cgroup's
//! limit and half of what `ulimit -v`/`-d` leave above what the process maps). A refusal is a
//! `MemoryError` stating the need, what is held and the limit, before anything is allocated, so a
//! call never dies of a failed allocation.

use pyo3::PyResult;
use texel::texture::{Format, Limits};
use texel::MemoryBudget;

use crate::errors::to_py;

/// The budget of one call: `max_memory` bytes (held to what the machine and the process limits
/// allow), else the process's default.
pub(crate) fn budget(max_memory: Option<u64>) -> MemoryBudget {
    MemoryBudget::limit_or_default(max_memory)
}

/// Charge `bytes` that `what` will hold to `budget`, or raise `MemoryError` with the figures.
pub(crate) fn take(budget: &mut MemoryBudget, what: &str, bytes: u64) -> PyResult<()> {
    budget.take(what, bytes).map_err(|e| to_py(e, ""))
}

/// `n` values of `size` bytes each, saturating.
pub(crate) fn bytes_of(n: u64, size: usize) -> u64 {
    n.saturating_mul(size as u64)
}

/// What making a `width x height` texture from an array of `float` or 8-bit texels holds at its
/// peak: the RGBA copy of the array and the texture as it is built ([`Limits::texture_bytes`]:
/// the whole pyramid, which the copy grows into while both are held, and the linear scratch of
/// the levels below 0).
pub(crate) fn texture_bytes(width: u32, height: u32, float: bool) -> u64 {
    let format = if float {
        Format::Rgba32Float
    } else {
        Format::Rgba8Unorm
    };
    let copy = u64::from(width) * u64::from(height) * format.texel_bytes();
    copy.saturating_add(Limits::texture_bytes(width, height, format))
}
