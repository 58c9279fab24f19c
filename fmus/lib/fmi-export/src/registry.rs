//! Registry of live instance pointers.
//!
//! Importers hand us raw `void*` handles. Looking a handle up here *before* dereferencing it
//! turns NULL, freed, foreign (an FMI 2 handle passed to an FMI 3 function, or an instance of
//! another model in the same process) and garbage pointers into a clean `Error` instead of
//! undefined behaviour. The lock is held only for the lookup, never during model code.

use std::any::TypeId;
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

/// Which C API created an instance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Api {
    Fmi3,
    Fmi2,
}

type Key = (TypeId, Api);

fn table() -> &'static Mutex<HashMap<usize, Key>> {
    static TABLE: OnceLock<Mutex<HashMap<usize, Key>>> = OnceLock::new();
    TABLE.get_or_init(|| Mutex::new(HashMap::new()))
}

fn lock() -> std::sync::MutexGuard<'static, HashMap<usize, Key>> {
    table().lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

pub fn insert(addr: usize, ty: TypeId, api: Api) {
    lock().insert(addr, (ty, api));
}

/// Removes `addr` if it is a live instance of that type and API; true if it was.
pub fn remove(addr: usize, ty: TypeId, api: Api) -> bool {
    let mut t = lock();
    if t.get(&addr) == Some(&(ty, api)) {
        t.remove(&addr);
        true
    } else {
        false
    }
}

pub fn contains(addr: usize, ty: TypeId, api: Api) -> bool {
    lock().get(&addr) == Some(&(ty, api))
}
