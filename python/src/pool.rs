//! The worker threads every call runs on: one rayon pool per process, made on first use.
//!
//! A forked child (`os.fork`, `multiprocessing`'s `fork` start method) inherits the parent's
//! memory but none of its threads, so a pool made before the fork has no workers in the child
//! and any work handed to it waits for ever. The pool is therefore recorded with the id of the
//! process that made it, and a call in another process makes that process's own pool. The
//! parent's pool is left as it is in the child (its workers' locks and queues may have been
//! mid-use at the fork, so it is neither used nor dropped). rayon's global pool is never used:
//! [`crate::run_released_on`] installs the work in a pool of this module's, so every parallel
//! loop of texel's under it (texture pyramids, rendering with `threads=None`) runs there too.

use std::sync::{Arc, Mutex};

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::PyResult;
use rayon::{ThreadPool, ThreadPoolBuilder};

/// The most worker threads a call may ask for.
pub(crate) const MAX_THREADS: usize = 1024;

/// This process's pool and the id of the process that made it.
///
/// Locked only by [`shared`], which callers reach with the GIL held: a fork from Python holds
/// the GIL too, so no thread holds this lock when a process forks.
static POOL: Mutex<Option<(u32, Arc<ThreadPool>)>> = Mutex::new(None);

/// A `threads=` argument, checked: 1 to [`MAX_THREADS`], or `None` for the process's pool.
pub(crate) fn threads_of(threads: Option<usize>) -> PyResult<Option<usize>> {
    match threads {
        Some(n) if !(1..=MAX_THREADS).contains(&n) => Err(PyValueError::new_err(format!(
            "threads must be 1 to {MAX_THREADS}, or None for all cores; got {n}"
        ))),
        t => Ok(t),
    }
}

/// A pool of `threads` workers (`None`: rayon's default, `RAYON_NUM_THREADS` or one per core).
fn build(threads: Option<usize>) -> PyResult<ThreadPool> {
    let mut b = ThreadPoolBuilder::new().thread_name(|k| format!("texel-{k}"));
    if let Some(n) = threads {
        b = b.num_threads(n);
    }
    b.build()
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start texel's worker threads: {e}")))
}

/// This process's pool, made on first use in this process (see the module's notes on forks).
pub(crate) fn shared() -> PyResult<Arc<ThreadPool>> {
    let pid = std::process::id();
    let mut slot = POOL.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((owner, pool)) = slot.as_ref() {
        if *owner == pid {
            return Ok(Arc::clone(pool));
        }
    }
    if let Some(inherited) = slot.take() {
        // Made by the parent before a fork: it has no workers here and its state is not to be
        // touched, not even by its destructor.
        std::mem::forget(inherited);
    }
    let pool = Arc::new(build(None)?);
    *slot = Some((pid, Arc::clone(&pool)));
    Ok(pool)
}

/// The pool a call with `threads=` runs on: the process's pool for `None`, else a pool of its own
/// with that many workers.
pub(crate) fn for_threads(threads: Option<usize>) -> PyResult<Arc<ThreadPool>> {
    match threads_of(threads)? {
        None => shared(),
        Some(n) => Ok(Arc::new(build(Some(n))?)),
    }
}
