//! Message ports on a model's [`Store`]: a Binary variable holding a frame list
//! ([`agrisim_frames`]) plus its Int64 counter `<port>_seq`, so that a model publishes and
//! takes messages one by one and never loses one between an importer's exchanges.
//!
//! A producing model calls [`OutPort::publish`] for each message and [`OutPort::sync`] at the
//! end of `initialize` and of every `do_step`; a consuming model calls [`InPort::take`] at
//! the start of a step. Every model with an output port declares [`port_window`].

use crate::store::Store;
use crate::var::{Start, Var};
pub use agrisim_frames::{max_size as frames_max_size, Frame, MEDIA_TYPE};
use agrisim_frames::{Cursor, Outbox};

/// The parameter every model with message outputs declares: how long a message stays in
/// its port. An importer that reads the port at least this often loses nothing.
pub const fn port_window() -> Var {
    Var::param("port_window", Start::Float64(0.1)).unit("s").range(0.001, 1.0).desc(
        "Each message stays this long in its message port (a frame list of every message since): read message ports at least this often",
    )
}

/// [`port_window`]'s value in `io` at index `i`, in whole nanoseconds.
pub fn window_ns(io: &Store, i: usize) -> Result<i64, String> {
    let w = io.f64(i);
    if !(w.is_finite() && w > 0.0) {
        return Err(format!("parameter port_window must be positive, got {w}"));
    }
    Ok((w * 1e9).round() as i64)
}

/// An output message port: Binary variable `bin`, counter `seq`.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct OutPort {
    bin: usize,
    seq: usize,
    outbox: Outbox,
}

impl OutPort {
    pub fn new(bin: usize, seq: usize) -> OutPort {
        OutPort { bin, seq, outbox: Outbox::default() }
    }

    /// Forgets every message and restarts the numbering (call in `initialize`).
    pub fn clear(&mut self) {
        self.outbox.clear();
    }

    /// Queues a message (CDR) stamped `stamp_ns`; it enters the port at the next [`OutPort::sync`].
    pub fn publish(&mut self, stamp_ns: i64, cdr: Vec<u8>) {
        self.outbox.push(stamp_ns, cdr);
    }

    /// Number of messages published since the last [`OutPort::clear`].
    pub fn count(&self) -> u64 {
        self.outbox.last_seq()
    }

    /// Writes the port as it stands at `now_ns` (the model's time after the step) to `io`.
    pub fn sync(&mut self, io: &mut Store, now_ns: i64, window_ns: i64) {
        let fresh = io.binary(self.bin).is_empty();
        if self.outbox.advance(now_ns, window_ns) || fresh {
            self.outbox.encode(io.binary_mut(self.bin));
        }
        io.set_i64(self.seq, self.outbox.last_seq() as i64);
    }
}

/// An input message port: Binary variable `bin`, counter `seq`.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct InPort {
    bin: usize,
    seq: usize,
    cursor: Cursor,
}

impl InPort {
    pub fn new(bin: usize, seq: usize) -> InPort {
        InPort { bin, seq, cursor: Cursor::default() }
    }

    /// Forgets what was taken (call in `initialize`).
    pub fn clear(&mut self) {
        self.cursor = Cursor::default();
    }

    /// The messages written to the input since the last call, oldest first (a frame list,
    /// or one bare CDR message when the counter moved); an error names the variable.
    pub fn take(&mut self, io: &Store, name: &str) -> Result<Vec<Vec<u8>>, String> {
        let counter = io.i64(self.seq).max(0) as u64;
        let frames = self.cursor.take_input(io.binary(self.bin), counter).map_err(|e| format!("input {name}: {e}"))?;
        Ok(frames.into_iter().map(|f| f.payload.to_vec()).collect())
    }
}

/// The messages (CDR) in output port `bin` of `io`, oldest first: for tests and tools that
/// drive a model directly. Panics on a malformed list (a bug in the model).
pub fn messages(io: &Store, bin: usize) -> Vec<&[u8]> {
    agrisim_frames::decode(io.binary(bin))
        .expect("a model's output port holds a valid frame list")
        .into_iter()
        .map(|f| f.payload)
        .collect()
}

/// The newest message in output port `bin` of `io` (empty when the port is empty).
pub fn latest(io: &Store, bin: usize) -> &[u8] {
    messages(io, bin).pop().unwrap_or(&[])
}
