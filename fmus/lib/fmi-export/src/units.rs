//! SI base-unit exponents of the unit names models use, for `<BaseUnit>` in
//! modelDescription.xml. Unknown names are still declared, just without a `<BaseUnit>`.

/// Exponents of (kg, m, s, A, K, mol, cd, rad) and the factor to SI.
pub struct BaseUnit {
    pub exponents: [i8; 8],
    pub factor: f64,
}

pub const EXPONENT_NAMES: [&str; 8] = ["kg", "m", "s", "A", "K", "mol", "cd", "rad"];

/// The base-unit decomposition of `name`, if known.
pub fn base_unit(name: &str) -> Option<BaseUnit> {
    let (e, factor): ([i8; 8], f64) = match name {
        "1" => ([0, 0, 0, 0, 0, 0, 0, 0], 1.0),
        "kg" => ([1, 0, 0, 0, 0, 0, 0, 0], 1.0),
        "m" => ([0, 1, 0, 0, 0, 0, 0, 0], 1.0),
        "mm" => ([0, 1, 0, 0, 0, 0, 0, 0], 1e-3),
        "s" => ([0, 0, 1, 0, 0, 0, 0, 0], 1.0),
        "ms" => ([0, 0, 1, 0, 0, 0, 0, 0], 1e-3),
        "1/s" | "Hz" => ([0, 0, -1, 0, 0, 0, 0, 0], 1.0),
        "m/s" => ([0, 1, -1, 0, 0, 0, 0, 0], 1.0),
        "m/s2" => ([0, 1, -2, 0, 0, 0, 0, 0], 1.0),
        "m2" => ([0, 2, 0, 0, 0, 0, 0, 0], 1.0),
        "rad" => ([0, 0, 0, 0, 0, 0, 0, 1], 1.0),
        "deg" => ([0, 0, 0, 0, 0, 0, 0, 1], std::f64::consts::PI / 180.0),
        "rad/s" => ([0, 0, -1, 0, 0, 0, 0, 1], 1.0),
        "rad/s2" => ([0, 0, -2, 0, 0, 0, 0, 1], 1.0),
        "N" => ([1, 1, -2, 0, 0, 0, 0, 0], 1.0),
        "N.m" => ([1, 2, -2, 0, 0, 0, 0, 0], 1.0),
        "W" => ([1, 2, -3, 0, 0, 0, 0, 0], 1.0),
        "J" => ([1, 2, -2, 0, 0, 0, 0, 0], 1.0),
        "Pa" => ([1, -1, -2, 0, 0, 0, 0, 0], 1.0),
        "V" => ([1, 2, -3, -1, 0, 0, 0, 0], 1.0),
        "A" => ([0, 0, 0, 1, 0, 0, 0, 0], 1.0),
        "K" => ([0, 0, 0, 0, 1, 0, 0, 0], 1.0),
        "kg.m2" => ([1, 2, 0, 0, 0, 0, 0, 0], 1.0),
        _ => return None,
    };
    Some(BaseUnit { exponents: e, factor })
}
