//! The logger callback handed to each FMU instance, and the per-instance buffer it fills.
//!
//! Each instance gets its own [`LogSink`] as `instanceEnvironment`, so messages are attributed
//! to the right instance even when several instances share one loaded library. Messages carry
//! a sequence number so the wrapper can pick out exactly the messages logged during one call
//! (for its error, or to print its warnings) while the whole stream stays available to
//! `take_log`. With debug logging off an FMU calls back only for warnings and errors, and the
//! wrapper's per-call cost is one atomic load (no lock, no allocation).

use std::collections::VecDeque;
use std::ffi::{c_char, c_void, CStr};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use super::status::Status;

/// One message an FMU sent through the logger callback.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LogMessage {
    pub status: Status,
    pub category: String,
    pub message: String,
}

/// Unread messages kept per instance; older ones are dropped past this, so an FMU that logs
/// every step cannot grow memory without bound when nobody calls `take_log`.
const CAPACITY: usize = 4096;

#[derive(Default)]
pub(crate) struct LogSink {
    inner: Mutex<VecDeque<(u64, LogMessage)>>,
    /// Messages received so far (the next one's sequence number); written under the lock,
    /// read without it.
    received: AtomicU64,
    /// `received` at the last [`LogSink::take`].
    taken: AtomicU64,
}

impl LogSink {
    pub(crate) fn push(&self, msg: LogMessage) {
        let mut g = self.inner.lock().unwrap_or_else(|p| p.into_inner());
        let seq = self.received.load(Ordering::Relaxed);
        if g.len() == CAPACITY {
            g.pop_front();
        }
        g.push_back((seq, msg));
        self.received.store(seq + 1, Ordering::Release);
    }

    /// Sequence number the next message will get: a mark before a call. Also the number of
    /// messages received since the instance was created.
    pub(crate) fn mark(&self) -> u64 {
        self.received.load(Ordering::Acquire)
    }

    /// Copies of the messages logged since `mark` (none, without locking, when there are none).
    pub(crate) fn since(&self, mark: u64) -> Vec<LogMessage> {
        if self.mark() == mark {
            return Vec::new();
        }
        let g = self.inner.lock().unwrap_or_else(|p| p.into_inner());
        g.iter().filter(|(s, _)| *s >= mark).map(|(_, m)| m.clone()).collect()
    }

    pub(crate) fn take(&self) -> Vec<LogMessage> {
        // Called every step by a session (for warnings): nothing new costs no lock.
        if self.mark() == self.taken.load(Ordering::Acquire) {
            return Vec::new();
        }
        let mut g = self.inner.lock().unwrap_or_else(|p| p.into_inner());
        self.taken.store(self.mark(), Ordering::Release);
        g.drain(..).map(|(_, m)| m).collect()
    }
}

unsafe fn lossy(p: *const c_char) -> String {
    if p.is_null() {
        String::new()
    } else {
        CStr::from_ptr(p).to_string_lossy().into_owned()
    }
}

/// `fmi3LogMessageCallback`. `env` is the `LogSink` of the calling instance.
pub(crate) unsafe extern "C" fn log_callback(
    env: *mut c_void,
    status: std::ffi::c_int,
    category: *const c_char,
    message: *const c_char,
) {
    // Nothing may unwind into the FMU.
    let _ = std::panic::catch_unwind(|| {
        if env.is_null() {
            return;
        }
        // SAFETY: env is the address of a LogSink boxed by the Instance, which outlives the
        // FMU instance (freed before the box is dropped); strings are NUL-terminated per FMI.
        let sink = &*(env as *const LogSink);
        sink.push(LogMessage { status: Status::from_raw(status), category: lossy(category), message: lossy(message) });
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marks_select_one_calls_messages() {
        let sink = LogSink::default();
        let m = |s: &str| LogMessage { status: Status::Ok, category: "c".into(), message: s.into() };
        sink.push(m("a"));
        let mark = sink.mark();
        sink.push(m("b"));
        assert_eq!(sink.since(mark), vec![m("b")]);
        assert_eq!(sink.take().len(), 2);
        assert!(sink.since(0).is_empty());
    }

    #[test]
    fn capacity_bounds_memory() {
        let sink = LogSink::default();
        for i in 0..CAPACITY + 10 {
            sink.push(LogMessage { status: Status::Ok, category: String::new(), message: i.to_string() });
        }
        let all = sink.take();
        assert_eq!(all.len(), CAPACITY);
        assert_eq!(all[0].message, "10");
    }
}
