//! The binary format of agrisim message ports.
//!
//! An FMI 3 Binary message port carries every message its FMU produced in the last
//! `port_window` seconds of simulation time, not only the newest one, so an importer that
//! exchanges at least that often loses nothing. Each message is a *frame* with its own
//! sequence number (1, 2, 3, ... per port) and stamp, in the spirit of the FMI-LS-BUS network
//! abstraction layer, which also packs 0..n operations into one Binary per exchange. A
//! consumer keeps the last sequence number it took and skips the frames at or below it (an
//! importer exchanging more often than the window sees a frame more than once); a jump in
//! the sequence numbers means messages were lost (the importer exchanged less often than the
//! window).
//!
//! Layout (all integers little-endian):
//!
//! ```text
//! header  "AGF" 0x01 (magic and format version 1)  u32 frame count
//! frame   u64 sequence number  i64 stamp [ns]  u32 payload length  payload
//! ```
//!
//! The payload is one ROS 2 message in CDR with its 4-byte encapsulation header. The port's
//! mimeType is `application/x-ros2-cdr-frames; version=1; type=pkg/msg/Type`; the port's
//! Int64 counter `<port>_seq` holds the sequence number of the newest frame, so a simple
//! importer still sees that something arrived. An input port accepts frames, or one bare CDR
//! message (taken as new when the input's counter changes).

use std::collections::VecDeque;
use std::fmt;

/// First four bytes of a frame list: magic "AGF" and the format version.
pub const MAGIC: [u8; 4] = *b"AGF\x01";
/// Media type of a framed message port (the ROS 2 type and version follow as parameters).
pub const MEDIA_TYPE: &str = "application/x-ros2-cdr-frames";
/// Format version written in the magic and in the mimeType.
pub const VERSION: u32 = 1;
/// Bytes of the list header and of each frame header.
pub const HEADER_LEN: usize = 8;
pub const FRAME_HEADER_LEN: usize = 20;

/// Size bound of a frame list of at most `count` messages of at most `payload` bytes each
/// (a port's FMI `maxSize`).
pub const fn max_size(payload: usize, count: usize) -> usize {
    HEADER_LEN + count * (FRAME_HEADER_LEN + payload)
}

/// Whether `mime` names a framed port (any parameters).
pub fn is_framed_mime(mime: &str) -> bool {
    mime.split(';').next().is_some_and(|m| m.trim() == MEDIA_TYPE)
}

/// Whether `bytes` start like a frame list (a bare CDR message starts with its
/// encapsulation header 0x00 0x0?, never with "AGF").
pub fn is_frame_list(bytes: &[u8]) -> bool {
    bytes.len() >= 4 && bytes[..4] == MAGIC
}

/// One message of a frame list.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frame<'a> {
    pub seq: u64,
    pub stamp_ns: i64,
    pub payload: &'a [u8],
}

/// Why bytes are not a valid frame list, or why frames were lost.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Error {
    /// Not a frame list (wrong magic or version), or truncated, or with trailing bytes.
    Malformed(String),
    /// Messages `first..=last` were produced but are no longer in the port.
    Gap { first: u64, last: u64 },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Malformed(why) => write!(f, "not a valid message frame list: {why}"),
            Error::Gap { first, last } if first == last => write!(f, "message {first} was lost (sequence gap)"),
            Error::Gap { first, last } => write!(f, "messages {first} to {last} were lost (sequence gap)"),
        }
    }
}

impl std::error::Error for Error {}

/// Appends the frame list of `frames` to `out`.
pub fn encode_into<'a>(out: &mut Vec<u8>, frames: impl ExactSizeIterator<Item = Frame<'a>>) {
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&(frames.len() as u32).to_le_bytes());
    for f in frames {
        out.extend_from_slice(&f.seq.to_le_bytes());
        out.extend_from_slice(&f.stamp_ns.to_le_bytes());
        out.extend_from_slice(&(f.payload.len() as u32).to_le_bytes());
        out.extend_from_slice(f.payload);
    }
}

/// The frames of a frame list, checked: whole, no trailing bytes, sequence numbers rising.
pub fn decode(bytes: &[u8]) -> Result<Vec<Frame<'_>>, Error> {
    let bad = |why: String| Error::Malformed(why);
    if bytes.len() < HEADER_LEN {
        return Err(bad(format!("{} bytes, shorter than the {HEADER_LEN}-byte header", bytes.len())));
    }
    if bytes[..3] != MAGIC[..3] {
        return Err(bad(format!("starts with {:02x?}, not the magic \"AGF\"", &bytes[..4])));
    }
    if bytes[3] != MAGIC[3] {
        return Err(bad(format!("format version {}, this reader knows version {VERSION}", bytes[3])));
    }
    let count = u32::from_le_bytes(bytes[4..8].try_into().unwrap()) as usize;
    let mut at = HEADER_LEN;
    // Each frame takes at least its header: a count larger than that is a lie, not a reason
    // to allocate.
    if count > (bytes.len() - at) / FRAME_HEADER_LEN {
        return Err(bad(format!("{count} frames announced but only {} bytes follow", bytes.len() - at)));
    }
    let mut frames = Vec::with_capacity(count);
    for i in 0..count {
        if bytes.len() - at < FRAME_HEADER_LEN {
            return Err(bad(format!("frame {i} of {count}: header truncated")));
        }
        let h = &bytes[at..at + FRAME_HEADER_LEN];
        let seq = u64::from_le_bytes(h[0..8].try_into().unwrap());
        let stamp_ns = i64::from_le_bytes(h[8..16].try_into().unwrap());
        let len = u32::from_le_bytes(h[16..20].try_into().unwrap()) as usize;
        at += FRAME_HEADER_LEN;
        if bytes.len() - at < len {
            return Err(bad(format!("frame {i} of {count}: payload of {len} bytes truncated to {}", bytes.len() - at)));
        }
        if let Some(prev) = frames.last().map(|f: &Frame| f.seq) {
            if seq <= prev {
                return Err(bad(format!("frame {i}: sequence number {seq} does not follow {prev}")));
            }
        }
        frames.push(Frame { seq, stamp_ns, payload: &bytes[at..at + len] });
        at += len;
    }
    if at != bytes.len() {
        return Err(bad(format!("{} trailing bytes after {count} frames", bytes.len() - at)));
    }
    Ok(frames)
}

/// A consumer's position in one port: the last sequence number taken.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Cursor {
    pub last: u64,
}

impl Cursor {
    /// The frames of `bytes` after the last one taken, in order, and moves past them.
    /// `counter` is the port's `<port>_seq` (the newest sequence number produced): frames
    /// between the last one taken and the first one present, or missing up to `counter`,
    /// were lost, which is an [`Error::Gap`] (the cursor then moves past them, so a caller
    /// that chooses to go on is not told twice).
    pub fn take<'a>(&mut self, bytes: &'a [u8], counter: u64) -> Result<Vec<Frame<'a>>, Error> {
        let frames: Vec<Frame> = decode(bytes)?.into_iter().filter(|f| f.seq > self.last).collect();
        let first_present = frames.first().map_or(counter + 1, |f| f.seq);
        let newest = frames.last().map_or(counter, |f| f.seq.max(counter));
        if first_present > self.last + 1 && newest > self.last {
            let gap = Error::Gap { first: self.last + 1, last: first_present.min(counter + 1) - 1 };
            self.last = newest;
            return Err(gap);
        }
        if let Some(f) = frames.last() {
            self.last = f.seq;
        }
        Ok(frames)
    }

    /// An input's new messages: frames after the last one taken (a sender that skipped
    /// sequence numbers is not an error here), or, when `bytes` is one bare message and the
    /// input's counter moved past the last one taken, that message.
    pub fn take_input<'a>(&mut self, bytes: &'a [u8], counter: u64) -> Result<Vec<Frame<'a>>, Error> {
        if !is_frame_list(bytes) {
            if counter == self.last {
                return Ok(vec![]);
            }
            self.last = counter;
            return Ok(vec![Frame { seq: counter, stamp_ns: 0, payload: bytes }]);
        }
        let frames: Vec<Frame> = decode(bytes)?.into_iter().filter(|f| f.seq > self.last).collect();
        if let Some(f) = frames.last() {
            self.last = f.seq;
        }
        Ok(frames)
    }
}

#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
struct Pending {
    seq: u64,
    stamp_ns: i64,
    /// Simulation time from which the frame is in the port; None until [`Outbox::advance`].
    visible_ns: Option<i64>,
    payload: Vec<u8>,
}

/// A producer's side of one port: the frames of the last window, and the sequence counter.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Outbox {
    frames: VecDeque<Pending>,
    last_seq: u64,
}

impl Outbox {
    /// Forgets every frame and restarts the numbering (a model's initialization).
    pub fn clear(&mut self) {
        self.frames.clear();
        self.last_seq = 0;
    }

    /// Queues a message stamped `stamp_ns`; it enters the port at the next
    /// [`Outbox::advance`]. Returns its sequence number.
    pub fn push(&mut self, stamp_ns: i64, payload: Vec<u8>) -> u64 {
        self.last_seq += 1;
        self.frames.push_back(Pending { seq: self.last_seq, stamp_ns, visible_ns: None, payload });
        self.last_seq
    }

    /// Sequence number of the newest message (0 before the first).
    pub fn last_seq(&self) -> u64 {
        self.last_seq
    }

    /// The port at simulation time `now_ns`: messages queued since the last call become
    /// visible now, and those visible since `now_ns - window_ns` or earlier leave (an importer
    /// reading every `window_ns` has seen them). Returns whether the content changed.
    pub fn advance(&mut self, now_ns: i64, window_ns: i64) -> bool {
        let mut changed = false;
        for f in self.frames.iter_mut().rev() {
            if f.visible_ns.is_some() {
                break;
            }
            f.visible_ns = Some(now_ns);
            changed = true;
        }
        while self.frames.front().is_some_and(|f| f.visible_ns.is_some_and(|v| v <= now_ns - window_ns)) {
            self.frames.pop_front();
            changed = true;
        }
        changed
    }

    /// Number of messages in the port (visible ones).
    pub fn len(&self) -> usize {
        self.visible().count()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn visible(&self) -> impl ExactSizeIterator<Item = Frame<'_>> + '_ {
        let n = self.frames.iter().take_while(|f| f.visible_ns.is_some()).count();
        self.frames.iter().take(n).map(|f| Frame { seq: f.seq, stamp_ns: f.stamp_ns, payload: &f.payload })
    }

    /// Replaces `out` with the port's frame list.
    pub fn encode(&self, out: &mut Vec<u8>) {
        out.clear();
        encode_into(out, self.visible());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn list(frames: &[(u64, i64, &[u8])]) -> Vec<u8> {
        let mut out = vec![];
        encode_into(&mut out, frames.iter().map(|&(seq, stamp_ns, payload)| Frame { seq, stamp_ns, payload }));
        out
    }

    #[test]
    fn round_trip_and_layout() {
        let bytes = list(&[(1, 5, b"ab"), (2, -7, b"")]);
        assert_eq!(&bytes[..8], b"AGF\x01\x02\x00\x00\x00");
        assert_eq!(bytes.len(), max_size(2, 2) - 2);
        let f = decode(&bytes).unwrap();
        assert_eq!(
            f,
            vec![Frame { seq: 1, stamp_ns: 5, payload: b"ab" }, Frame { seq: 2, stamp_ns: -7, payload: b"" }]
        );
        assert!(is_frame_list(&bytes) && !is_frame_list(&[0, 1, 0, 0, 1, 0, 0, 0, 0]));
        assert!(is_framed_mime("application/x-ros2-cdr-frames; version=1; type=a/msg/B"));
        assert!(!is_framed_mime("application/x-ros2-cdr; type=a/msg/B"));
    }

    #[test]
    fn malformed_lists_are_refused_with_a_reason() {
        let good = list(&[(1, 0, b"abc"), (2, 0, b"d")]);
        for cut in 0..good.len() {
            assert!(matches!(decode(&good[..cut]), Err(Error::Malformed(_))), "cut at {cut}");
        }
        let mut trailing = good.clone();
        trailing.push(0);
        assert!(decode(&trailing).unwrap_err().to_string().contains("trailing"));
        let mut v2 = good.clone();
        v2[3] = 2;
        assert!(decode(&v2).unwrap_err().to_string().contains("version 2"));
        assert!(decode(&list(&[(2, 0, b""), (2, 0, b"")])).unwrap_err().to_string().contains("does not follow"));
        let mut huge = list(&[]);
        huge[4..8].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(decode(&huge).unwrap_err().to_string().contains("announced"));
    }

    #[test]
    fn window_keeps_each_message_for_one_exchange_period() {
        let mut o = Outbox::default();
        o.push(0, vec![0]);
        assert!(o.advance(0, 100));
        assert_eq!(o.len(), 1);
        for k in 1..=10 {
            o.push(k * 20 - 5, vec![k as u8]);
            o.advance(k * 20, 100);
        }
        // At t = 200 the messages visible from 120 to 200 remain (4 of them: 120 is not > 100).
        let mut out = vec![];
        o.encode(&mut out);
        let seqs: Vec<u64> = decode(&out).unwrap().iter().map(|f| f.seq).collect();
        assert_eq!(seqs, vec![7, 8, 9, 10, 11]);
        assert_eq!(o.last_seq(), 11);
    }

    #[test]
    fn cursor_reports_gaps_and_skips_repeats() {
        let mut c = Cursor::default();
        assert_eq!(c.take(&list(&[(1, 0, b"a"), (2, 0, b"b")]), 2).unwrap().len(), 2);
        assert_eq!(c.take(&list(&[(2, 0, b"b"), (3, 0, b"c")]), 3).unwrap().len(), 1);
        assert_eq!(c.take(&list(&[(6, 0, b"f")]), 6), Err(Error::Gap { first: 4, last: 5 }));
        assert_eq!(c.last, 6);
        // Everything expired although the counter moved on.
        assert_eq!(c.take(&list(&[]), 8), Err(Error::Gap { first: 7, last: 8 }));
        assert_eq!(c.take(&list(&[]), 8).unwrap().len(), 0);
    }

    #[test]
    fn inputs_take_frames_or_one_bare_message() {
        let mut c = Cursor::default();
        let bare = [0u8, 1, 0, 0, 7];
        assert!(c.take_input(&bare, 0).unwrap().is_empty());
        assert_eq!(c.take_input(&bare, 1).unwrap()[0].payload, &bare);
        assert!(c.take_input(&bare, 1).unwrap().is_empty());
        assert_eq!(c.take_input(&list(&[(1, 0, b"x"), (5, 0, b"y")]), 5).unwrap().len(), 1);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]
        /// Random bytes, and valid lists with bytes flipped or cut: decode and the cursors
        /// answer an error or frames, never panic.
        #[test]
        fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..200), flip in any::<usize>(), cut in any::<usize>()) {
            let _ = decode(&bytes);
            let mut good = list(&[(1, 0, &bytes[..bytes.len() / 2]), (2, 5, &bytes[bytes.len() / 2..])]);
            let i = flip % good.len();
            good[i] ^= 0x5a;
            let good = &good[..good.len() - cut % good.len()];
            let _ = decode(good);
            let _ = Cursor::default().take(good, flip as u64);
            let _ = Cursor::default().take_input(good, cut as u64);
        }

        /// Any producer schedule read every `read` ns with a window of at least `read` ns
        /// delivers every message exactly once, in order; a shorter window is caught as a gap.
        #[test]
        fn reader_sees_every_message_once(counts in prop::collection::vec(0usize..4, 1..60), read in 1i64..6, window in 1i64..8) {
            let (step, mut o, mut c) = (10i64, Outbox::default(), Cursor::default());
            let (mut got, mut gap) = (vec![], false);
            let mut bytes = vec![];
            for (k, &n) in counts.iter().enumerate() {
                for _ in 0..n {
                    let stamp = k as i64 * step;
                    o.push(stamp, stamp.to_le_bytes().to_vec());
                }
                let now = (k as i64 + 1) * step;
                o.advance(now, window * step);
                if (k as i64 + 1) % read == 0 {
                    o.encode(&mut bytes);
                    match c.take(&bytes, o.last_seq()) {
                        Ok(f) => got.extend(f.iter().map(|f| f.seq)),
                        Err(Error::Gap { .. }) => gap = true,
                        Err(e) => panic!("{e}"),
                    }
                }
            }
            let read_upto = counts.len() as i64 / read * read;
            let produced: u64 = counts[..read_upto as usize].iter().sum::<usize>() as u64;
            if window >= read {
                prop_assert!(!gap);
                prop_assert_eq!(got, (1..=produced).collect::<Vec<_>>());
            } else if gap {
                prop_assert!(got.len() < produced as usize);
            }
        }
    }
}
