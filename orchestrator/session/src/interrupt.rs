//! A stop request (SIGINT, SIGTERM, or a caller) that runs honour at the next step boundary,
//! so the MCAP is finished and a benchmark's completed trials are summarized. The CLI
//! installs the signal handler; a second signal exits at once.

use std::sync::atomic::{AtomicBool, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// The error message of a run stopped by a request (benchmarks recognise it).
pub const INTERRUPTED: &str = "interrupted";

/// Asks every run in this process to stop at its next step boundary; returns whether a stop
/// had been asked for already.
pub fn request() -> bool {
    REQUESTED.swap(true, Ordering::SeqCst)
}

/// Whether a stop was asked for.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::SeqCst)
}

/// Forgets a request (tests, or a program that goes on after handling one).
pub fn clear() {
    REQUESTED.store(false, Ordering::SeqCst);
}
