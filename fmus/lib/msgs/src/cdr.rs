//! OMG CDR (XCDR1) as used by ROS 2 (`rmw_fastrtps`, rosbag2 "cdr" encoding).
//!
//! Layout rules, all of which peers rely on byte-for-byte:
//! * a 4-byte encapsulation header: `[0x00, 0x01, 0x00, 0x00]` = CDR little-endian;
//! * every primitive is aligned to its own size (1, 2, 4 or 8 bytes), measured from the
//!   first byte *after* the header (so an `f64` right after the header needs no padding);
//! * `string` = `u32` length counting the terminating NUL, the UTF-8 bytes, then the NUL;
//! * unbounded sequence (`T[]`) = `u32` element count, then the elements;
//! * fixed-size array (`T[N]`) = the N elements, no count.
//!
//! The reader treats its input as untrusted (messages arrive from FMUs and files): it
//! never panics and never allocates more than the remaining input could possibly hold.

use std::fmt;

/// Encapsulation header for CDR little-endian with no options: what ROS 2 writes on every
/// little-endian machine, and what [`CdrWriter`] always writes.
pub const CDR_LE_HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Size of the encapsulation header; alignment is measured from this offset.
pub const HEADER_LEN: usize = 4;

/// Why a CDR buffer could not be decoded. Every variant carries the byte offset in the
/// *whole* buffer (header included) so a bad message can be located in a hex dump.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CdrError {
    /// The buffer is shorter than the 4-byte encapsulation header.
    MissingHeader { len: usize },
    /// The encapsulation kind is not plain CDR (BE `00 00` or LE `00 01`), e.g. XCDR2 or PL_CDR.
    UnsupportedEncapsulation { kind: [u8; 2] },
    /// The buffer ended while reading `what`.
    UnexpectedEof { what: &'static str, offset: usize, needed: usize, available: usize },
    /// A length or count field announces more data than the rest of the buffer holds.
    LengthTooLarge { what: &'static str, offset: usize, length: u64, available: usize },
    /// String bytes are not valid UTF-8.
    InvalidUtf8 { offset: usize },
    /// A string's last byte (at `offset`) is not the NUL terminator.
    MissingNul { offset: usize, found: u8 },
    /// A `bool` byte other than 0 or 1.
    InvalidBool { offset: usize, value: u8 },
}

impl fmt::Display for CdrError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CdrError::MissingHeader { len } => {
                write!(f, "CDR buffer of {len} bytes is too short for the 4-byte encapsulation header")
            }
            CdrError::UnsupportedEncapsulation { kind } => write!(
                f,
                "unsupported CDR encapsulation kind {:02x} {:02x} at byte 0 \
                 (expected 00 01 for CDR_LE or 00 00 for CDR_BE)",
                kind[0], kind[1]
            ),
            CdrError::UnexpectedEof { what, offset, needed, available } => write!(
                f,
                "CDR data truncated reading {what} at byte {offset}: \
                 need {needed} bytes, {available} left"
            ),
            CdrError::LengthTooLarge { what, offset, length, available } => {
                write!(f, "CDR {what} at byte {offset} announces {length} but only {available} bytes remain")
            }
            CdrError::InvalidUtf8 { offset } => {
                write!(f, "CDR string starting at byte {offset} is not valid UTF-8")
            }
            CdrError::MissingNul { offset, found } => {
                write!(f, "CDR string not NUL-terminated: byte {offset} is 0x{found:02x}, expected 0x00")
            }
            CdrError::InvalidBool { offset, value } => {
                write!(f, "CDR bool at byte {offset} has value {value}, expected 0 or 1")
            }
        }
    }
}

impl std::error::Error for CdrError {}

/// Serializes into CDR little-endian, header included.
///
/// Writing cannot fail; the only limit is that a string or sequence longer than
/// `u32::MAX` cannot be represented in CDR (that panics, as it is a caller bug, not data).
#[derive(Debug, Clone)]
pub struct CdrWriter {
    buf: Vec<u8>,
}

impl Default for CdrWriter {
    fn default() -> Self {
        Self::new()
    }
}

impl CdrWriter {
    /// A writer holding just the CDR_LE encapsulation header.
    pub fn new() -> Self {
        Self::with_capacity(64)
    }

    /// Like [`CdrWriter::new`] with room for `capacity` payload bytes (avoids regrowth in
    /// per-step recording).
    pub fn with_capacity(capacity: usize) -> Self {
        let mut buf = Vec::with_capacity(capacity.saturating_add(HEADER_LEN));
        buf.extend_from_slice(&CDR_LE_HEADER);
        Self { buf }
    }

    /// Bytes written so far, header included.
    pub fn as_bytes(&self) -> &[u8] {
        &self.buf
    }

    /// The finished buffer (header + payload, no trailing padding).
    pub fn into_bytes(self) -> Vec<u8> {
        self.buf
    }

    /// Pads with zeros so the next write starts at a multiple of `n` after the header.
    pub fn align(&mut self, n: usize) {
        let rel = self.buf.len() - HEADER_LEN;
        let pad = (n - rel % n) % n;
        self.buf.resize(self.buf.len() + pad, 0);
    }

    pub fn write_bool(&mut self, v: bool) {
        self.buf.push(v as u8);
    }
    pub fn write_u8(&mut self, v: u8) {
        self.buf.push(v);
    }
    pub fn write_i8(&mut self, v: i8) {
        self.buf.push(v as u8);
    }
    pub fn write_u16(&mut self, v: u16) {
        self.align(2);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn write_i16(&mut self, v: i16) {
        self.align(2);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn write_u32(&mut self, v: u32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn write_i32(&mut self, v: i32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn write_u64(&mut self, v: u64) {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn write_i64(&mut self, v: i64) {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn write_f32(&mut self, v: f32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn write_f64(&mut self, v: f64) {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// `u32` length (bytes + 1 for the NUL), the bytes, the NUL.
    pub fn write_string(&mut self, s: &str) {
        let len = u32::try_from(s.len() + 1).expect("CDR string longer than u32::MAX");
        self.write_u32(len);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    /// The `u32` element count that starts an unbounded sequence.
    pub fn write_sequence_len(&mut self, len: usize) {
        let len = u32::try_from(len).expect("CDR sequence longer than u32::MAX");
        self.write_u32(len);
    }
}

/// Deserializes CDR (either byte order, as announced by the header) from a borrowed buffer.
#[derive(Debug, Clone)]
pub struct CdrReader<'a> {
    data: &'a [u8],
    pos: usize,
    little_endian: bool,
}

macro_rules! read_prim {
    ($name:ident, $t:ty, $what:literal) => {
        #[doc = concat!("Reads an aligned `", stringify!($t), "`.")]
        pub fn $name(&mut self) -> Result<$t, CdrError> {
            const N: usize = std::mem::size_of::<$t>();
            self.align(N);
            let b = self.take(N, $what)?;
            let mut a = [0u8; N];
            a.copy_from_slice(b);
            Ok(if self.little_endian { <$t>::from_le_bytes(a) } else { <$t>::from_be_bytes(a) })
        }
    };
}

impl<'a> CdrReader<'a> {
    /// Checks the encapsulation header and positions the reader after it.
    /// The two option bytes are ignored (ROS 2 peers use them only for padding hints).
    pub fn new(data: &'a [u8]) -> Result<Self, CdrError> {
        if data.len() < HEADER_LEN {
            return Err(CdrError::MissingHeader { len: data.len() });
        }
        let little_endian = match [data[0], data[1]] {
            [0x00, 0x01] => true,
            [0x00, 0x00] => false,
            kind => return Err(CdrError::UnsupportedEncapsulation { kind }),
        };
        Ok(Self { data, pos: HEADER_LEN, little_endian })
    }

    /// Current offset in the whole buffer (header included).
    pub fn position(&self) -> usize {
        self.pos
    }

    /// Bytes not yet consumed (trailing padding counts as remaining; it is allowed).
    pub fn remaining(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }

    /// Skips padding so the next read starts at a multiple of `n` after the header.
    /// Never moves past the end: a following read then reports the truncation.
    pub fn align(&mut self, n: usize) {
        let rel = self.pos - HEADER_LEN;
        let pad = (n - rel % n) % n;
        self.pos = (self.pos + pad).min(self.data.len());
    }

    fn take(&mut self, n: usize, what: &'static str) -> Result<&'a [u8], CdrError> {
        let available = self.remaining();
        if n > available {
            return Err(CdrError::UnexpectedEof { what, offset: self.pos, needed: n, available });
        }
        let s = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    /// `n` bytes at once (a `uint8[]` body: images, point clouds).
    pub fn read_bytes(&mut self, n: usize) -> Result<&'a [u8], CdrError> {
        self.take(n, "uint8 array")
    }

    pub fn read_u8(&mut self) -> Result<u8, CdrError> {
        Ok(self.take(1, "uint8")?[0])
    }
    pub fn read_i8(&mut self) -> Result<i8, CdrError> {
        Ok(self.take(1, "int8")?[0] as i8)
    }
    pub fn read_bool(&mut self) -> Result<bool, CdrError> {
        let offset = self.pos;
        match self.take(1, "bool")?[0] {
            0 => Ok(false),
            1 => Ok(true),
            value => Err(CdrError::InvalidBool { offset, value }),
        }
    }
    read_prim!(read_u16, u16, "uint16");
    read_prim!(read_i16, i16, "int16");
    read_prim!(read_u32, u32, "uint32");
    read_prim!(read_i32, i32, "int32");
    read_prim!(read_u64, u64, "uint64");
    read_prim!(read_i64, i64, "int64");
    read_prim!(read_f32, f32, "float32");
    read_prim!(read_f64, f64, "float64");

    /// Reads a string. A length of 0 (no NUL at all) is accepted as the empty string,
    /// as Fast CDR does; otherwise the last byte must be NUL and the rest valid UTF-8.
    pub fn read_string(&mut self) -> Result<String, CdrError> {
        let len_offset = {
            self.align(4);
            self.pos
        };
        let len = self.read_u32()? as usize;
        if len == 0 {
            return Ok(String::new());
        }
        if len > self.remaining() {
            return Err(CdrError::LengthTooLarge {
                what: "string length",
                offset: len_offset,
                length: len as u64,
                available: self.remaining(),
            });
        }
        let start = self.pos;
        let bytes = self.take(len, "string")?;
        let (body, nul) = bytes.split_at(len - 1);
        if nul[0] != 0 {
            return Err(CdrError::MissingNul { offset: start + len - 1, found: nul[0] });
        }
        match std::str::from_utf8(body) {
            Ok(s) => Ok(s.to_owned()),
            Err(_) => Err(CdrError::InvalidUtf8 { offset: start }),
        }
    }

    /// Reads a sequence count and rejects it unless `count * min_elem_size` bytes could
    /// still follow, so a garbage count can neither allocate nor loop for long.
    pub fn read_sequence_len(&mut self, min_elem_size: usize) -> Result<usize, CdrError> {
        self.align(4);
        let offset = self.pos;
        let count = self.read_u32()? as usize;
        let need = count.saturating_mul(min_elem_size.max(1));
        if need > self.remaining() {
            return Err(CdrError::LengthTooLarge {
                what: "sequence count",
                offset,
                length: count as u64,
                available: self.remaining(),
            });
        }
        Ok(count)
    }
}

/// A value with a CDR encoding: primitives, strings, sequences, fixed arrays and every
/// message type. Message structs are encoded as the concatenation of their fields, so
/// implementing this per field type is all a message needs.
pub trait CdrField: Sized {
    /// Fewest bytes an encoded value can occupy (padding excluded). Used to bound sequence
    /// counts against the remaining input before allocating (a 0 is treated as 1 there).
    const MIN_SIZE: usize;
    fn write_field(&self, w: &mut CdrWriter);
    fn read_field(r: &mut CdrReader<'_>) -> Result<Self, CdrError>;

    /// The elements of a sequence (after its count), one by one; bytes override it with one
    /// copy (images and clouds are megabytes of them).
    fn write_items(items: &[Self], w: &mut CdrWriter) {
        for v in items {
            v.write_field(w);
        }
    }

    /// `n` elements of a sequence (after its count; `n` already checked against the input).
    fn read_items(r: &mut CdrReader<'_>, n: usize) -> Result<Vec<Self>, CdrError> {
        let mut v = Vec::with_capacity(n);
        for _ in 0..n {
            v.push(Self::read_field(r)?);
        }
        Ok(v)
    }

    /// Reads past one value, failing exactly where [`CdrField::read_field`] would, without
    /// building it: checking a message needs no copy of an image's bytes.
    fn skip_field(r: &mut CdrReader<'_>) -> Result<(), CdrError> {
        Self::read_field(r).map(drop)
    }

    /// [`CdrField::read_items`] without building them.
    fn skip_items(r: &mut CdrReader<'_>, n: usize) -> Result<(), CdrError> {
        (0..n).try_for_each(|_| Self::skip_field(r))
    }
}

macro_rules! prim_field {
    ($t:ty, $w:ident, $r:ident) => {
        impl CdrField for $t {
            const MIN_SIZE: usize = std::mem::size_of::<$t>();
            fn write_field(&self, w: &mut CdrWriter) {
                w.$w(*self)
            }
            fn read_field(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
                r.$r()
            }
        }
    };
}
prim_field!(bool, write_bool, read_bool);
prim_field!(i8, write_i8, read_i8);
prim_field!(u16, write_u16, read_u16);
prim_field!(i16, write_i16, read_i16);
prim_field!(u32, write_u32, read_u32);
prim_field!(i32, write_i32, read_i32);
prim_field!(u64, write_u64, read_u64);
prim_field!(i64, write_i64, read_i64);
prim_field!(f32, write_f32, read_f32);
prim_field!(f64, write_f64, read_f64);

impl CdrField for String {
    const MIN_SIZE: usize = 4;
    fn write_field(&self, w: &mut CdrWriter) {
        w.write_string(self)
    }
    fn read_field(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        r.read_string()
    }
}

impl CdrField for u8 {
    const MIN_SIZE: usize = 1;
    fn write_field(&self, w: &mut CdrWriter) {
        w.write_u8(*self)
    }
    fn read_field(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        r.read_u8()
    }
    fn write_items(items: &[Self], w: &mut CdrWriter) {
        w.buf.extend_from_slice(items);
    }
    fn read_items(r: &mut CdrReader<'_>, n: usize) -> Result<Vec<Self>, CdrError> {
        Ok(r.read_bytes(n)?.to_vec())
    }
    fn skip_items(r: &mut CdrReader<'_>, n: usize) -> Result<(), CdrError> {
        r.read_bytes(n).map(drop)
    }
}

/// Unbounded sequence `T[]`.
impl<T: CdrField> CdrField for Vec<T> {
    const MIN_SIZE: usize = 4;
    fn write_field(&self, w: &mut CdrWriter) {
        w.write_sequence_len(self.len());
        T::write_items(self, w);
    }
    fn read_field(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        let n = r.read_sequence_len(T::MIN_SIZE)?;
        // `n` is bounded by the remaining input (checked above), so this is safe to reserve.
        T::read_items(r, n)
    }
    fn skip_field(r: &mut CdrReader<'_>) -> Result<(), CdrError> {
        let n = r.read_sequence_len(T::MIN_SIZE)?;
        T::skip_items(r, n)
    }
}

/// Fixed-size array `T[N]` (no count on the wire).
impl<T: CdrField + Copy + Default, const N: usize> CdrField for [T; N] {
    const MIN_SIZE: usize = N * T::MIN_SIZE;
    fn write_field(&self, w: &mut CdrWriter) {
        for v in self {
            v.write_field(w);
        }
    }
    fn read_field(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        let mut a = [T::default(); N];
        for slot in a.iter_mut() {
            *slot = T::read_field(r)?;
        }
        Ok(a)
    }
}
