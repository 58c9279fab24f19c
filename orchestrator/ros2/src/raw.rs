//! Raw CDR samples on DDS: the bytes a message has on the bus (4-byte encapsulation header +
//! body) go on the wire as they are; received ones come back with their header, whatever the
//! peer's byte order. Checking them is the bridge's job, not the transport's.

use rustdds::no_key::{Decode, DefaultDecoder, DeserializerAdapter, SerializerAdapter};
use rustdds::{bytes::Bytes, RepresentationIdentifier};
use std::io;

/// A whole CDR message, encapsulation header included.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RawCdr(pub Vec<u8>);

/// The adapter that moves [`RawCdr`] unchanged.
pub struct RawAdapter;

impl SerializerAdapter<RawCdr> for RawAdapter {
    type Error = io::Error;

    fn output_encoding() -> RepresentationIdentifier {
        RepresentationIdentifier::CDR_LE
    }

    /// The body after the header (RustDDS writes the representation identifier itself).
    /// Our writer is little-endian only; a big-endian message is refused, never mislabelled.
    fn to_bytes(value: &RawCdr) -> Result<Bytes, io::Error> {
        match value.0.get(..2) {
            Some([0x00, 0x01]) => Ok(Bytes::copy_from_slice(&value.0[4..])),
            _ => Err(io::Error::new(io::ErrorKind::InvalidData, "not a little-endian CDR message")),
        }
    }
}

impl DeserializerAdapter<RawCdr> for RawAdapter {
    type Error = io::Error;
    type Decoded = RawCdr;

    fn supported_encodings() -> &'static [RepresentationIdentifier] {
        &[RepresentationIdentifier::CDR_LE, RepresentationIdentifier::CDR_BE]
    }

    fn transform_decoded(decoded: RawCdr) -> RawCdr {
        decoded
    }
}

/// Puts the header back in front of the body.
#[derive(Clone, Copy)]
pub struct RawDecoder;

impl<'de> Decode<'de, RawCdr> for RawDecoder {
    type Error = io::Error;

    fn decode_bytes(self, input: &'de [u8], encoding: RepresentationIdentifier) -> Result<RawCdr, io::Error> {
        let mut v = Vec::with_capacity(input.len() + 4);
        v.extend_from_slice(&encoding.to_bytes());
        v.extend_from_slice(&[0, 0]);
        v.extend_from_slice(input);
        Ok(RawCdr(v))
    }
}

impl DefaultDecoder<RawCdr> for RawAdapter {
    type Decoder = RawDecoder;
    const DECODER: RawDecoder = RawDecoder;
}
