//! FMU-state arguments (live, freed, garbage, NULL) and the serialize / deserialize round
//! trip the fuzzers issue on them.

use std::ffi::c_void;

use agrisim_fmi::{Mode, Status};

use crate::args::garbage_ptr;
use crate::rng::FuzzRng;
use crate::shadow::{Must, Shadow, Then};

/// Serializes a live state, deserializes it as a new state and checks that the copy
/// serializes to the very same bytes; sometimes corrupts the bytes first (refused or
/// accepted, never a crash). A state that cannot be serialized gets junk bytes, which must
/// be refused. Only the deserialize call may fail (its outcome is the one checked).
pub(crate) unsafe fn round_trip(
    rng: &mut FuzzRng,
    sh: &Shadow,
    size: impl Fn(*mut c_void, *mut usize) -> Status,
    serialize: impl Fn(*mut c_void, *mut u8, usize) -> Status,
    deserialize: impl Fn(*const u8, usize, *mut *mut c_void) -> Status,
    free: impl Fn(*mut *mut c_void) -> Status,
) -> (Must, Then, Status) {
    let (src, good) = pick_state(rng, sh);
    let live = sh.mode != Mode::Fatal && good && sh.states.iter().any(|s| s.0 == src && s.1 != Mode::Error);
    let mut p = std::ptr::null_mut();
    if !live {
        let junk = [b'A', b'G', b'S', 1, 0, 7];
        let s = deserialize(junk.as_ptr(), rng.below(junk.len() + 1), &mut p);
        return (Must::Fail, Then::Nothing, s);
    }
    let mut n = 0usize;
    assert!(size(src, &mut n) <= Status::Warning, "SerializedFMUStateSize failed on a live state");
    let mut bytes = vec![0u8; n];
    assert!(serialize(src, bytes.as_mut_ptr(), n) <= Status::Warning, "SerializeFMUState failed on a live state");
    if rng.chance(10) {
        let i = rng.below(bytes.len());
        bytes[i] ^= 1 << rng.below(8);
        bytes.truncate(bytes.len() - rng.below(2) * rng.below(bytes.len()));
        let s = deserialize(bytes.as_ptr(), bytes.len(), &mut p);
        if s <= Status::Warning {
            // Accepted (a flipped bit in a value): not tracked, so freed at once.
            assert!(free(&mut p) <= Status::Warning);
        }
        return (Must::Any, Then::Nothing, s);
    }
    let s = deserialize(bytes.as_ptr(), bytes.len(), &mut p);
    if s > Status::Warning {
        return (Must::Succeed, Then::Nothing, s);
    }
    let mut again = 0usize;
    assert!(
        size(p, &mut again) <= Status::Warning && again == n,
        "a deserialized state must serialize to the same size"
    );
    let mut copy = vec![0u8; again];
    assert!(serialize(p, copy.as_mut_ptr(), again) <= Status::Warning);
    assert!(copy == bytes, "a deserialized state must serialize to the same bytes");
    (Must::Succeed, Then::Copied(src, p), s)
}

/// A state pointer: live (true), freed, garbage or NULL (false).
pub(crate) fn pick_state(rng: &mut FuzzRng, sh: &Shadow) -> (*mut c_void, bool) {
    match rng.below(10) {
        0 => (std::ptr::null_mut(), false),
        1 => (garbage_ptr(rng), false),
        2 if !sh.freed.is_empty() => {
            let p = sh.freed[rng.below(sh.freed.len())];
            // A freed address may have been reused by a newer live state.
            (p, sh.states.iter().any(|s| s.0 == p))
        }
        _ if !sh.states.is_empty() => (sh.states[rng.below(sh.states.len())].0, true),
        _ => (garbage_ptr(rng), false),
    }
}
