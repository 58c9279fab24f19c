//! Random arguments for the API calls: value references, C values for the setters, array
//! sizes, garbage pointers.

use std::ffi::{c_char, c_void, CString};

use agrisim_fmi::ctype::{self, CType};
use agrisim_fmi::{Model, Value};

use crate::rng::FuzzRng;

/// Things whose pointers are handed to the FMU during one call.
#[derive(Default)]
pub(crate) struct Keep {
    pub(crate) strings: Vec<CString>,
    pub(crate) bytes: Vec<Vec<u8>>,
}

pub(crate) fn garbage_ptr(rng: &mut FuzzRng) -> *mut c_void {
    // Never dereferenced by a correct layer: only compared against its registries.
    (0x1000 + (rng.next_u64() % 0xFFFF_0000) * 8) as *mut c_void
}

/// Value references: mostly ones accepting `T`, sometimes any, sometimes unknown.
pub(crate) fn pick_vrs<M: Model, T: CType>(rng: &mut FuzzRng, fmi2_only: bool) -> Vec<u32> {
    let n = match rng.below(6) {
        0 => 0,
        1 => 2 + rng.below(3),
        _ => 1,
    };
    let visible = |i: usize| !fmi2_only || M::VARIABLES[i].fmi2_representable();
    let mut matching: Vec<u32> = (0..M::VARIABLES.len())
        .filter(|&i| visible(i) && T::accepts(&Value::from_start(&M::VARIABLES[i].start)))
        .map(|i| i as u32 + 1)
        .collect();
    if T::accepts(&Value::Float64(0.0)) {
        matching.push(0);
    }
    (0..n)
        .map(|_| match rng.below(10) {
            0 => rng.pick(&[M::VARIABLES.len() as u32 + 1, u32::MAX, 1_000_000]),
            1 | 2 => rng.below(M::VARIABLES.len() + 1) as u32,
            _ if !matching.is_empty() => rng.pick(&matching),
            _ => rng.below(M::VARIABLES.len() + 1) as u32,
        })
        .collect()
}

/// True when every reference in `vrs` is visible and of a type `T` can access.
pub(crate) fn all_match<M: Model, T: CType>(vrs: &[u32], fmi2_only: bool) -> bool {
    vrs.iter().all(|&vr| {
        if vr == 0 {
            return T::accepts(&Value::Float64(0.0));
        }
        match M::VARIABLES.get(vr as usize - 1) {
            Some(v) => (!fmi2_only || v.fmi2_representable()) && T::accepts(&Value::from_start(&v.start)),
            None => false,
        }
    })
}

/// Random C values for the setters.
pub(crate) trait Gen: CType {
    fn gen(rng: &mut FuzzRng, keep: &mut Keep) -> Self::C;
}

macro_rules! gen_int {
    ($($m:ident),*) => {$(
        impl Gen for ctype::$m {
            fn gen(rng: &mut FuzzRng, _: &mut Keep) -> Self::C {
                rng.int() as Self::C
            }
        }
    )*};
}
gen_int!(Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Bool2);

impl Gen for ctype::Float64 {
    fn gen(rng: &mut FuzzRng, _: &mut Keep) -> f64 {
        rng.f64()
    }
}
impl Gen for ctype::Float32 {
    fn gen(rng: &mut FuzzRng, _: &mut Keep) -> f32 {
        rng.f64() as f32
    }
}
impl Gen for ctype::Bool3 {
    fn gen(rng: &mut FuzzRng, _: &mut Keep) -> u8 {
        rng.pick(&[0, 1, 1, 2, 255])
    }
}
impl Gen for ctype::Str {
    fn gen(rng: &mut FuzzRng, keep: &mut Keep) -> *const c_char {
        let s = match rng.below(8) {
            0 => return std::ptr::null(),
            1 => CString::new(vec![0xC3u8, 0x28]).unwrap_or_default(), // invalid UTF-8
            2 => CString::new("äöü <&> \"quoted\" 100%").unwrap_or_default(),
            _ => CString::new(format!("s{}", rng.next_u64() % 1000)).unwrap_or_default(),
        };
        keep.strings.push(s);
        keep.strings.last().map_or(std::ptr::null(), |s| s.as_ptr())
    }
}
impl Gen for ctype::Bin {
    fn gen(rng: &mut FuzzRng, keep: &mut Keep) -> (usize, *const u8) {
        match rng.below(8) {
            0 => (1 + rng.below(4), std::ptr::null()),
            1 => (0, std::ptr::null()),
            _ => {
                let n = rng.below(64);
                keep.bytes.push((0..n).map(|_| rng.next_u64() as u8).collect());
                let b = keep.bytes.last().map_or(&[][..], |b| &b[..]);
                (b.len(), b.as_ptr())
            }
        }
    }
}

/// Array sizes for a get/set: (nValues, NULL values array?) and whether they are right.
pub(crate) fn sizes(rng: &mut FuzzRng, n_vr: usize) -> (usize, bool, bool) {
    match rng.below(12) {
        0 => (n_vr + 1, false, false),
        1 if n_vr > 0 => (n_vr - 1, false, false),
        2 if n_vr > 0 => (n_vr, true, false),
        _ => (n_vr, false, true),
    }
}

pub(crate) fn zeroed<T>(n: usize) -> Vec<T> {
    // SAFETY: only instantiated with C number/pointer types, for which all-zero is valid.
    (0..n).map(|_| unsafe { std::mem::zeroed() }).collect()
}
