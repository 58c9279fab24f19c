//! Scenario families: `[greenhouse.family]` gives ranges instead of values, and each scene
//! seed draws one greenhouse from them. A benchmark's `--scenes K` grows scene k from the
//! greenhouse seed + k, so scene k is draw k of the family: the draw is a pure function of
//! the greenhouse `seed` and the ranges, made while the `[greenhouse]` text is parsed
//! ([`crate::GreenhouseConfig::from_toml_str`]), so the world FMU, the sensors and the judge,
//! all parsing the same text, build the same greenhouse.
//!
//! Ranges are `[low, high]`, inclusive for counts; a key that is absent is not drawn. A key
//! given both as a range here and as a value in `[greenhouse]` is an error.

use agrisim_math::Rng;
use serde::Deserialize;

/// Stream label of family draws (the generator's streams are 1-3: see `generate`).
const FAMILY: u64 = 0xFA_0111;

/// The ranges of `[greenhouse.family]`.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FamilyConfig {
    /// Aisle width [m], e.g. [1.6, 2.2].
    pub aisle_width: Option<[f64; 2]>,
    /// Fruit per truss, e.g. [3, 8].
    pub fruit_per_truss: Option<[usize; 2]>,
    /// Leaf blobs per plant, e.g. [4, 14].
    pub leaf_density: Option<[usize; 2]>,
    /// Mean fruit radius [m], e.g. [0.020, 0.040].
    pub fruit_radius: Option<[f64; 2]>,
    /// Bottom of the fruit band [m]: `fruit_height[0]` is drawn from it.
    pub fruit_height_low: Option<[f64; 2]>,
    /// Top of the fruit band [m]: `fruit_height[1]` is drawn from it.
    pub fruit_height_high: Option<[f64; 2]>,
    /// Trusses per plant.
    pub trusses_per_plant: Option<[usize; 2]>,
    /// Plant spacing along a row [m].
    pub plant_spacing: Option<[f64; 2]>,
}

/// The `[greenhouse]` key each family range replaces (fruit_height_low/high both `fruit_height`).
fn target(key: &str) -> &str {
    match key {
        "fruit_height_low" | "fruit_height_high" => "fruit_height",
        k => k,
    }
}

impl FamilyConfig {
    /// The keys of the ranges that are set.
    fn keys(&self) -> Vec<&'static str> {
        let mut k = vec![];
        let f = |set: bool, name: &'static str, k: &mut Vec<&'static str>| {
            if set {
                k.push(name)
            }
        };
        f(self.aisle_width.is_some(), "aisle_width", &mut k);
        f(self.fruit_per_truss.is_some(), "fruit_per_truss", &mut k);
        f(self.leaf_density.is_some(), "leaf_density", &mut k);
        f(self.fruit_radius.is_some(), "fruit_radius", &mut k);
        f(self.fruit_height_low.is_some(), "fruit_height_low", &mut k);
        f(self.fruit_height_high.is_some(), "fruit_height_high", &mut k);
        f(self.trusses_per_plant.is_some(), "trusses_per_plant", &mut k);
        f(self.plant_spacing.is_some(), "plant_spacing", &mut k);
        k
    }

    /// Checks the ranges; errors name the key (`greenhouse.family.KEY`).
    pub fn validate(&self) -> Result<(), String> {
        let err = |key: &str, msg: String| Err(format!("greenhouse.family.{key}: {msg}"));
        for (k, r) in [
            ("aisle_width", self.aisle_width),
            ("fruit_radius", self.fruit_radius),
            ("fruit_height_low", self.fruit_height_low),
            ("fruit_height_high", self.fruit_height_high),
            ("plant_spacing", self.plant_spacing),
        ] {
            if let Some([a, b]) = r {
                if !(a.is_finite() && b.is_finite() && a > 0.0 && a <= b) {
                    return err(k, format!("must be [low, high] with 0 < low <= high, got [{a}, {b}]"));
                }
            }
        }
        for (k, r, min) in [
            ("fruit_per_truss", self.fruit_per_truss, 0),
            ("leaf_density", self.leaf_density, 0),
            ("trusses_per_plant", self.trusses_per_plant, 0),
        ] {
            if let Some([a, b]) = r {
                if a < min || a > b || b > 1000 {
                    return err(k, format!("must be [low, high] with low <= high <= 1000, got [{a}, {b}]"));
                }
            }
        }
        if let (Some([_, lo_hi]), Some([hi_lo, _])) = (self.fruit_height_low, self.fruit_height_high) {
            if lo_hi >= hi_lo {
                return err(
                    "fruit_height_low",
                    format!("its top {lo_hi} must lie below the bottom {hi_lo} of fruit_height_high"),
                );
            }
        }
        Ok(())
    }

    /// This family's draw for the greenhouse `seed`. `explicit(key)` says whether
    /// `[greenhouse]` gives the key itself: a key both drawn and given is an error.
    pub fn draw(&self, seed: u64, explicit: &dyn Fn(&str) -> bool) -> Result<FamilyDraw, String> {
        self.validate()?;
        for k in self.keys() {
            if explicit(target(k)) {
                return Err(format!(
                    "greenhouse.family.{k}: greenhouse.{} is given too; give either the value or the range",
                    target(k)
                ));
            }
        }
        // One stream per key, so adding a range to a family leaves the other draws as they were.
        let real = |label: u64, [a, b]: [f64; 2]| Rng::stream(seed, &[FAMILY, label]).range(a, b);
        let count = |label: u64, [a, b]: [usize; 2]| {
            a + Rng::stream(seed, &[FAMILY, label]).scene_below((b - a + 1) as u64) as usize
        };
        Ok(FamilyDraw {
            aisle_width: self.aisle_width.map(|r| real(1, r)),
            fruit_per_truss: self.fruit_per_truss.map(|r| count(2, r)),
            leaf_density: self.leaf_density.map(|r| count(3, r)),
            fruit_radius: self.fruit_radius.map(|r| real(4, r)),
            fruit_height_low: self.fruit_height_low.map(|r| real(5, r)),
            fruit_height_high: self.fruit_height_high.map(|r| real(6, r)),
            trusses_per_plant: self.trusses_per_plant.map(|r| count(7, r)),
            plant_spacing: self.plant_spacing.map(|r| real(8, r)),
        })
    }
}

/// One greenhouse drawn from a family: the values to set (None: not drawn).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FamilyDraw {
    pub aisle_width: Option<f64>,
    pub fruit_per_truss: Option<usize>,
    pub leaf_density: Option<usize>,
    pub fruit_radius: Option<f64>,
    pub fruit_height_low: Option<f64>,
    pub fruit_height_high: Option<f64>,
    pub trusses_per_plant: Option<usize>,
    pub plant_spacing: Option<f64>,
}
