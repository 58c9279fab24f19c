//! Serialized FMU states (`fmi3SerializeFMUState`, `fmi2SerializeFMUstate`).
//!
//! Layout: `b"AGS\x01"`, then a postcard-encoded [`Header`] (model name, instantiation token,
//! mode, times and every variable's value), then the model's own bytes
//! ([`Model::save_state`](crate::Model::save_state)). A model writes only what changes over a
//! run; what it derives from its parameters (a scene mesh, a URDF) is rebuilt when the state
//! is deserialized, by initializing a fresh model with the saved values, or taken from this
//! instance's model when its parameters are the very same.
//!
//! postcard writes floats as their IEEE bits, so a round trip is exact: restoring a
//! deserialized state and stepping gives the same bytes as never having stopped.

use crate::state::Mode;
use crate::store::Store;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// First bytes of every serialized state (format version 1).
pub const MAGIC: &[u8; 4] = b"AGS\x01";

/// Everything of a state outside the model.
#[derive(Serialize, Deserialize)]
pub(crate) struct Header {
    pub model: String,
    pub token: String,
    pub mode: Mode,
    pub time: f64,
    pub start_time: f64,
    pub stop_time: Option<f64>,
    pub store: Store,
    /// Length of the model's bytes that follow the header.
    pub model_len: u64,
}

/// Appends `value`'s postcard encoding to `out` (for [`Model::save_state`](crate::Model::save_state)).
pub fn write<T: Serialize + ?Sized>(value: &T, out: &mut Vec<u8>) -> Result<(), String> {
    let bytes = postcard::to_stdvec(value).map_err(|e| format!("cannot serialize the model state: {e}"))?;
    out.extend_from_slice(&bytes);
    Ok(())
}

/// Decodes a value written by [`write`]; every byte must be used.
pub fn read<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, String> {
    let (value, rest) =
        postcard::take_from_bytes(bytes).map_err(|e| format!("corrupt model state ({} bytes): {e}", bytes.len()))?;
    if !rest.is_empty() {
        return Err(format!("corrupt model state: {} bytes left over", rest.len()));
    }
    Ok(value)
}

pub(crate) fn encode(header: &Header, model: &[u8]) -> Result<Vec<u8>, String> {
    let mut out = MAGIC.to_vec();
    write(header, &mut out)?;
    out.extend_from_slice(model);
    Ok(out)
}

/// Splits a serialized state into its header and the model's bytes.
pub(crate) fn decode(bytes: &[u8]) -> Result<(Header, &[u8]), String> {
    let body = bytes.strip_prefix(MAGIC.as_slice()).ok_or_else(|| {
        format!("not a serialized agrisim FMU state ({} bytes; expected the prefix \"AGS\\x01\")", bytes.len())
    })?;
    let (header, rest): (Header, &[u8]) =
        postcard::take_from_bytes(body).map_err(|e| format!("corrupt FMU state header: {e}"))?;
    if rest.len() as u64 != header.model_len {
        return Err(format!(
            "corrupt FMU state: {} bytes of model state, the header says {} (truncated or padded)",
            rest.len(),
            header.model_len
        ));
    }
    Ok((header, rest))
}

/// [`Model::load_state`](crate::Model::load_state) for a model serialized whole with serde,
/// its derived parts `#[serde(skip)]`ped: decodes `bytes`, lets `keep` move the derived parts
/// over from the current model, and replaces it.
pub fn load_keeping<T: DeserializeOwned>(
    model: &mut T,
    bytes: &[u8],
    keep: impl FnOnce(&mut T, &mut T),
) -> Result<(), String> {
    let mut loaded: T = read(bytes)?;
    keep(&mut loaded, model);
    *model = loaded;
    Ok(())
}

/// `save_state` and `load_state` for a model whose every field is run state, serialized
/// whole with serde (put it inside `impl Model for ...`).
#[macro_export]
macro_rules! whole_state {
    () => {
        fn save_state(&self, out: &mut Vec<u8>) -> Result<(), $crate::ModelError> {
            $crate::serial::write(self, out)
        }

        fn load_state(&mut self, bytes: &[u8]) -> Result<(), $crate::ModelError> {
            *self = $crate::serial::read(bytes)?;
            Ok(())
        }
    };
}
