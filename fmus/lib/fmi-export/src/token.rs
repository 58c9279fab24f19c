//! The instantiation token (FMI 3 `instantiationToken`, FMI 2 `guid`) of a model: a hash of
//! everything in its interface, so that a modelDescription.xml and a binary of different
//! interfaces never instantiate together, and a token never has to be edited by hand.
//!
//! Hashed, in order: a scheme tag, the FMI version ("3.0" or "2.0"), the model identifier,
//! then per variable visible through that API: value reference, name, causality, variability,
//! type and start value (Binary bytes included), unit, min, max, mimeType, maxSize and the
//! declared initial dependencies. Descriptions are not part of the interface and are left out.
//! The hash is 128-bit FNV-1a over a length-prefixed encoding (no two tables encode alike),
//! written as a GUID: `{xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx}`.
//!
//! Everything is `const`: [`Model::TOKEN`](crate::Model::TOKEN) and
//! [`Model::GUID`](crate::Model::GUID) are computed at compile time.

use crate::var::{Causality, Start, Var, Variability};

/// Bump when the encoding below changes meaning.
const SCHEME: &str = "agrisim-fmi-token-1";

const FNV_OFFSET: u128 = 0x6c62272e07bb014262b821756295c58d;
const FNV_PRIME: u128 = 0x0000000001000000000000000000013B;

/// Length of a token: braces, 32 hex digits, 4 dashes.
pub const LEN: usize = 38;

struct Hasher(u128);

impl Hasher {
    const fn byte(self, b: u8) -> Hasher {
        Hasher((self.0 ^ b as u128).wrapping_mul(FNV_PRIME))
    }
    const fn u64(mut self, x: u64) -> Hasher {
        let b = x.to_le_bytes();
        let mut i = 0;
        while i < 8 {
            self = self.byte(b[i]);
            i += 1;
        }
        self
    }
    const fn bytes(mut self, b: &[u8]) -> Hasher {
        self = self.u64(b.len() as u64);
        let mut i = 0;
        while i < b.len() {
            self = self.byte(b[i]);
            i += 1;
        }
        self
    }
    const fn str(self, s: &str) -> Hasher {
        self.bytes(s.as_bytes())
    }
    const fn opt_f64(self, x: Option<f64>) -> Hasher {
        match x {
            None => self.byte(0),
            Some(x) => self.byte(1).u64(x.to_bits()),
        }
    }
    const fn var(self, vr: usize, v: &Var) -> Hasher {
        let mut h = self.u64(vr as u64).str(v.name);
        h = h.byte(match v.causality {
            Causality::Parameter => 0,
            Causality::CalculatedParameter => 1,
            Causality::Input => 2,
            Causality::Output => 3,
            Causality::Local => 4,
        });
        h = h.byte(match v.variability {
            Variability::Constant => 0,
            Variability::Fixed => 1,
            Variability::Tunable => 2,
            Variability::Discrete => 3,
            Variability::Continuous => 4,
        });
        h = match v.start {
            Start::Float64(x) => h.byte(0).u64(x.to_bits()),
            Start::Int32(x) => h.byte(1).u64(x as i64 as u64),
            Start::Int64(x) => h.byte(2).u64(x as u64),
            Start::Boolean(x) => h.byte(3).byte(x as u8),
            Start::String(s) => h.byte(4).str(s),
            Start::Binary(b) => h.byte(5).bytes(b),
        };
        h = h.str(v.unit).opt_f64(v.min).opt_f64(v.max).str(v.mime_type).u64(v.max_size as u64);
        match v.initial_dependencies {
            None => h.byte(0),
            Some(deps) => {
                h = h.byte(1).u64(deps.len() as u64);
                let mut i = 0;
                while i < deps.len() {
                    h = h.u64(deps[i] as u64);
                    i += 1;
                }
                h
            }
        }
    }
}

/// The hash of `vars` as seen through FMI `version` ("3.0": all; "2.0": only the
/// FMI-2-representable variables) for the model `name`.
pub const fn hash(version: &str, name: &str, vars: &[Var]) -> u128 {
    let fmi2 = matches!(version.as_bytes(), b"2.0");
    let mut h = Hasher(FNV_OFFSET).str(SCHEME).str(version).str(name);
    let mut i = 0;
    while i < vars.len() {
        if !fmi2 || vars[i].fmi2_representable() {
            h = h.var(i + 1, &vars[i]);
        }
        i += 1;
    }
    h.0
}

/// `hash` written as `{8-4-4-4-12}` lowercase hex.
pub const fn guid(hash: u128) -> [u8; LEN] {
    const HEX: &[u8; 16] = b"0123456789abcdef";
    let mut out = [0u8; LEN];
    out[0] = b'{';
    out[LEN - 1] = b'}';
    let mut pos = 1;
    let mut nibble = 0;
    while nibble < 32 {
        if matches!(nibble, 8 | 12 | 16 | 20) {
            out[pos] = b'-';
            pos += 1;
        }
        out[pos] = HEX[((hash >> (124 - 4 * nibble)) & 0xF) as usize];
        pos += 1;
        nibble += 1;
    }
    out
}

/// The token bytes as text (they are ASCII by construction).
pub const fn as_str(bytes: &[u8]) -> &str {
    match std::str::from_utf8(bytes) {
        Ok(s) => s,
        Err(_) => panic!("token bytes are ASCII"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: &[Var] = &[Var::input("u", 0.0), Var::output("y")];

    #[test]
    fn guid_format() {
        let g = guid(0x0123456789abcdef_fedcba9876543210);
        assert_eq!(as_str(&g), "{01234567-89ab-cdef-fedc-ba9876543210}");
    }

    #[test]
    fn every_interface_change_changes_the_hash() {
        let base = hash("3.0", "M", A);
        assert_eq!(base, hash("3.0", "M", A), "deterministic");
        let variants: [&[Var]; 8] = [
            &[Var::input("v", 0.0), Var::output("y")],
            &[Var::input("u", 1.0), Var::output("y")],
            &[Var::input("u", 0.0).unit("m"), Var::output("y")],
            &[Var::input("u", 0.0).range(-1.0, 1.0), Var::output("y")],
            &[Var::output("y"), Var::input("u", 0.0)],
            &[Var::input("u", 0.0), Var::output("y").init_depends_on(&[0])],
            &[Var::input("u", 0.0), Var::output("y").init_depends_on(&[])],
            &[Var::input("u", 0.0), Var::output("y"), Var::output("z")],
        ];
        for (k, v) in variants.iter().enumerate() {
            assert_ne!(hash("3.0", "M", v), base, "variant {k}");
        }
        assert_ne!(hash("3.0", "N", A), base);
        assert_ne!(hash("2.0", "M", A), base);
        // Descriptions are not part of the interface.
        assert_eq!(hash("3.0", "M", &[Var::input("u", 0.0).desc("input"), Var::output("y")]), base);
    }

    #[test]
    fn fmi2_hash_ignores_fmi3_only_variables() {
        let with_binary = [Var::input("u", 0.0), Var::output("y"), Var::output_discrete("b", Start::Binary(&[1]))];
        let other_binary = [Var::input("u", 0.0), Var::output("y"), Var::output_discrete("b", Start::Binary(&[2]))];
        assert_eq!(hash("2.0", "M", &with_binary), hash("2.0", "M", &other_binary));
        assert_ne!(hash("3.0", "M", &with_binary), hash("3.0", "M", &other_binary));
    }
}
