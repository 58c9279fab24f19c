//! A [`Snapshot`] as bytes: the whole system's state, to be written to a file and restored
//! later in this process or another (a fresh master of the same system, initialized).
//!
//! Layout: `b"AGSYS\x01"`, then postcard of `Saved`: the tick, each component's name, the
//! importer's state-machine state and the FMU's own serialized state
//! (`fmi3SerializeFMUState`), and each route's position (last sequence number taken, last
//! value written).

use crate::fmu::InstanceState;
use crate::{err, Master, Result, Snapshot};
use agrisim_frames::Cursor;
use serde::{Deserialize, Serialize};

const MAGIC: &[u8; 6] = b"AGSYS\x01";

#[derive(Serialize, Deserialize)]
struct Saved {
    tick: u64,
    fmus: Vec<SavedFmu>,
    routes: Vec<(u64, i64)>,
}

#[derive(Serialize, Deserialize)]
struct SavedFmu {
    component: String,
    state: InstanceState,
    bytes: Vec<u8>,
}

impl Master {
    /// The bytes of `snapshot` (every FMU must declare canSerializeFMUState).
    pub fn serialize_snapshot(&mut self, snapshot: &Snapshot) -> Result<Vec<u8>> {
        let mut fmus = Vec::with_capacity(snapshot.fmus.len());
        for (c, s) in self.system.components.iter_mut().zip(&snapshot.fmus) {
            let (bytes, state) =
                c.instance.serialize_state(s).map_err(|e| err!("serializing the state of FMU '{}': {e}", c.name))?;
            fmus.push(SavedFmu { component: c.name.clone(), state, bytes });
        }
        let routes = snapshot.routes.iter().map(|(c, w)| (c.last, *w)).collect();
        let mut out = MAGIC.to_vec();
        let body = postcard::to_stdvec(&Saved { tick: snapshot.tick, fmus, routes })
            .map_err(|e| err!("encoding the system snapshot: {e}"))?;
        out.extend_from_slice(&body);
        Ok(out)
    }

    /// A snapshot of this master from bytes of [`Master::serialize_snapshot`], taken from a
    /// master of the same system (same components in the same order, same routes).
    pub fn deserialize_snapshot(&mut self, bytes: &[u8]) -> Result<Snapshot> {
        let body = bytes.strip_prefix(MAGIC.as_slice()).ok_or_else(|| {
            err!("not a saved agrisim system snapshot (no \"AGSYS\\x01\" prefix; {} bytes)", bytes.len())
        })?;
        let saved: Saved = postcard::from_bytes(body).map_err(|e| err!("corrupt system snapshot: {e}"))?;
        let names: Vec<&str> = self.system.components.iter().map(|c| c.name.as_str()).collect();
        let saved_names: Vec<&str> = saved.fmus.iter().map(|f| f.component.as_str()).collect();
        if names != saved_names || saved.routes.len() != self.system.routes.len() {
            return Err(err!(
                "the snapshot is of another system: components {saved_names:?} and {} routes; this one has {names:?} and {}",
                saved.routes.len(),
                self.system.routes.len()
            ));
        }
        let mut fmus = Vec::with_capacity(saved.fmus.len());
        let mut failure = None;
        for (c, f) in self.system.components.iter_mut().zip(&saved.fmus) {
            match c.instance.deserialize_state(&f.bytes, f.state) {
                Ok(s) => fmus.push(s),
                Err(e) => {
                    failure = Some(err!("deserializing the state of FMU '{}': {e}", c.name));
                    break;
                }
            }
        }
        if let Some(e) = failure {
            // States made so far are freed now, not left until the instances go.
            for (c, s) in self.system.components.iter_mut().zip(fmus) {
                let _ = c.instance.free_state(s);
            }
            return Err(e);
        }
        let routes = saved.routes.iter().map(|&(last, written)| (Cursor { last }, written)).collect();
        Ok(Snapshot { fmus, tick: saved.tick, routes })
    }
}
