//! `--threads` as the libraries take it.

/// `--threads` as a worker count for [`texel::raster::on_threads`] and the settings' `threads`.
pub(crate) fn workers(threads: Option<u32>) -> Option<usize> {
    threads.map(|n| n as usize)
}

/// The number of threads work runs on: `threads`, or rayon's default (all cores).
pub(crate) fn thread_count(threads: Option<u32>) -> usize {
    workers(threads).unwrap_or_else(rayon::current_num_threads)
}
