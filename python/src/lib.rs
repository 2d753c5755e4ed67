//! `texel._texel`: the native half of the `texel` Python package.
//!
//! Arrays cross as numpy arrays (rust-numpy). Every call that works releases the GIL and runs
//! on texel's own threads, a pool per process ([`pool`], so a forked child gets its own);
//! while it runs, the calling thread wakes every [`POLL`] to let Python handle signals, so
//! Ctrl-C stops a reference after its current pass and raises `KeyboardInterrupt`. What a call
//! allocates in proportion to its input is charged to a memory budget first ([`memory`]).
//! texel's errors become Python exceptions carrying texel's messages ([`errors`]); a panic
//! becomes a `RuntimeError`, never an abort.

mod arrays;
mod errors;
mod memory;
mod pool;
mod scene;
mod texture;

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

/// How often a waiting call lets Python run its signal handlers (the worker wakes it sooner
/// when it finishes).
const POLL: Duration = Duration::from_millis(50);

/// [`run_released_on`] the process's pool ([`pool::shared`]).
pub(crate) fn run_released<R, F>(py: Python<'_>, work: F) -> PyResult<R>
where
    R: Send,
    F: FnOnce(&AtomicBool) -> PyResult<R> + Send,
{
    let pool = pool::shared()?;
    run_released_on(py, &pool, work)
}

/// Run `work` on another thread, installed in `pool` (its parallel loops, and those of everything
/// it calls, run on `pool`'s workers), with the GIL released, handing it a stop flag. When Python
/// reports a pending signal (Ctrl-C), the flag is set, `work` is waited for (it stops at its next
/// check, or finishes) and the signal's exception is raised.
pub(crate) fn run_released_on<R, F>(
    py: Python<'_>,
    pool: &rayon::ThreadPool,
    work: F,
) -> PyResult<R>
where
    R: Send,
    F: FnOnce(&AtomicBool) -> PyResult<R> + Send,
{
    let stop = AtomicBool::new(false);
    let done = AtomicBool::new(false);
    let caller = std::thread::current();
    std::thread::scope(|s| {
        let handle = s.spawn(|| {
            let result = pool.install(|| work(&stop));
            done.store(true, Ordering::Release);
            caller.unpark();
            result
        });
        let mut signal = None;
        while !done.load(Ordering::Acquire) && !handle.is_finished() {
            py.detach(|| std::thread::park_timeout(POLL));
            if signal.is_none() {
                if let Err(e) = py.check_signals() {
                    stop.store(true, Ordering::Relaxed);
                    signal = Some(e);
                }
            }
        }
        let result = handle.join().map_err(|panic| {
            let what = panic
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("a panic");
            PyRuntimeError::new_err(format!("texel failed internally: {what}"))
        });
        match signal {
            Some(e) => Err(e),
            None => result?,
        }
    })
}

/// The native module.
#[pymodule]
fn _texel(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<texture::Texture>()?;
    m.add_function(wrap_pyfunction!(scene::render, m)?)?;
    m.add_function(wrap_pyfunction!(scene::reference_estimate, m)?)?;
    m.add_function(wrap_pyfunction!(scene::compare, m)?)?;
    m.add_function(wrap_pyfunction!(scene::scene_size, m)?)?;
    m.add_function(wrap_pyfunction!(scene::scene_files, m)?)?;
    m.add_function(wrap_pyfunction!(texture::warp, m)?)?;
    m.add_function(wrap_pyfunction!(texture::encode, m)?)?;
    m.add("FILTERS", texel::Filter::NAMES.to_vec())?;
    let builtins: Vec<&str> = texel::scene::builtin_names()
        .iter()
        .chain(texel::scene::shaded_builtin_names())
        .copied()
        .collect();
    m.add("BUILTIN_SCENES", builtins)?;
    m.add("DEFAULT_SEED", texel::raster::DEFAULT_SEED)?;
    Ok(())
}
