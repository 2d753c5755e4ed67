//! Ctrl-C (SIGINT, SIGTERM, SIGHUP): by default texel deletes its unpublished temporary files
//! and exits with status 130. Work that can stop cleanly between steps (the reference, between pixel rows)
//! holds a [`Graceful`] guard: while it does, the first signal only raises a flag the work
//! reads, and a second one exits as usual.

use std::sync::atomic::{AtomicBool, Ordering};

/// Exit status after SIGINT, SIGTERM or SIGHUP (128 + SIGINT, as shells report an interrupt).
pub(crate) const INTERRUPTED: i32 = 130;

/// Whether a [`Graceful`] guard is held.
static GRACEFUL: AtomicBool = AtomicBool::new(false);

/// Raised by the first signal while a guard is held.
static STOP: AtomicBool = AtomicBool::new(false);

/// The signal handler.
pub(crate) fn on_signal() {
    if GRACEFUL.load(Ordering::SeqCst) && !STOP.swap(true, Ordering::SeqCst) {
        texel_io::stderr_text("\ntexel: stopping at the next pixel row (a second signal aborts)\n");
        return;
    }
    texel_io::remove_pending_and_exit(INTERRUPTED)
}

/// While alive, the first signal raises [`Graceful::flag`] instead of exiting.
pub(crate) struct Graceful(());

impl Graceful {
    /// Start handling signals gracefully.
    pub(crate) fn begin() -> Graceful {
        STOP.store(false, Ordering::SeqCst);
        GRACEFUL.store(true, Ordering::SeqCst);
        Graceful(())
    }

    /// The flag the first signal raises.
    pub(crate) fn flag(&self) -> &'static AtomicBool {
        &STOP
    }
}

impl Drop for Graceful {
    fn drop(&mut self) {
        GRACEFUL.store(false, Ordering::SeqCst);
    }
}

/// The error of work that a signal stopped after writing its partial result: `main` prints it
/// and exits with [`INTERRUPTED`].
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub(crate) struct Interrupted(pub String);
