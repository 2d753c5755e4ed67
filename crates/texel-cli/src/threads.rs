//! Running work on a chosen number of threads.

use anyhow::{Context, Result};

/// Run `f` on a rayon pool of `threads` workers, or on the global pool (all cores) for `None`.
pub fn with_threads<T: Send>(threads: Option<u32>, f: impl FnOnce() -> T + Send) -> Result<T> {
    match threads {
        None => Ok(f()),
        Some(n) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n as usize)
                .build()
                .context("cannot start worker threads")?;
            Ok(pool.install(f))
        }
    }
}

/// The number of threads work runs on: `threads`, or rayon's default (all cores).
pub fn thread_count(threads: Option<u32>) -> usize {
    threads.map_or_else(rayon::current_num_threads, |n| n as usize)
}
