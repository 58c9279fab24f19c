//! Colour of a surface: albedo by object kind, Lambert shading under the sun's beam plus
//! diffuse sky and floor light, at a fixed exposure, sRGB output.
//!
//! Albedos are plausible sRGB colours (not measurements). Tomato colour follows the six USDA
//! ripeness stages (USDA "United States Standards for Grades of Fresh Tomatoes", colour
//! classification): 1 green, 2 breaker, 3 turning, 4 pink, 5 light red, 6 red.
//!
//! Radiance = albedo x irradiance / exposure ([`irradiance`](crate::lighting::irradiance)): the sun's beam x cos(incidence)
//! x its unblocked fraction, plus diffuse sky light and light from the floor. Without an
//! environment the exposure is set so that a sunlit surface facing the sun shows its albedo;
//! with one, it is fixed at [`EXPOSURE`] W/m2, so dusk and cloud darken the image. Shading is
//! done on linear values and encoded with the sRGB transfer curve (IEC 61966-2-1).

use agrisim_scene::Kind;

/// Colour of rays that hit nothing (sky), sRGB.
pub const SKY: [u8; 3] = [170, 200, 235];

/// sRGB colour of a tomato at USDA stage 1..6 (clamped).
pub fn fruit_srgb(stage: u8) -> [u8; 3] {
    const STAGES: [[u8; 3]; 6] = [
        [88, 140, 42],  // 1 green
        [160, 168, 64], // 2 breaker: first tint
        [205, 150, 66], // 3 turning
        [226, 118, 86], // 4 pink
        [222, 68, 48],  // 5 light red
        [190, 26, 20],  // 6 red
    ];
    STAGES[(stage.clamp(1, 6) - 1) as usize]
}

pub fn albedo_srgb(kind: Kind) -> [u8; 3] {
    match kind {
        Kind::Floor => [150, 145, 135],
        Kind::Wall | Kind::Roof => [190, 205, 212],
        Kind::Post | Kind::Gutter => [172, 174, 178],
        Kind::HeatingPipe => [222, 222, 216],
        Kind::Stem | Kind::Truss => [96, 128, 52],
        Kind::Leaf => [58, 112, 38],
        Kind::Fruit { ripeness } => fruit_srgb(ripeness),
        Kind::Obstacle => [200, 122, 40],
        Kind::Robot => [228, 228, 228],
    }
}

/// Glass and clear film let sunlight through: they cast no shadow.
pub fn casts_shadow(kind: Kind) -> bool {
    !matches!(kind, Kind::Wall | Kind::Roof)
}

pub fn srgb_to_linear(c: u8) -> f64 {
    let c = c as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

pub fn linear_to_srgb(l: f64) -> u8 {
    let l = l.clamp(0.0, 1.0);
    let c = if l <= 0.0031308 { 12.92 * l } else { 1.055 * l.powf(1.0 / 2.4) - 0.055 };
    (c * 255.0).round() as u8
}

/// [`linear_to_srgb`] by table: the 255 linear values where the code steps up, found once by
/// bisecting `linear_to_srgb` itself, so the two agree exactly (the function is monotonic) and
/// a pixel costs two table reads instead of a `powf`.
pub fn encode_srgb(l: f64) -> u8 {
    srgb_table().encode(l)
}

/// An RGB pixel by [`encode_srgb`], the tables fetched once for the three.
#[inline]
pub fn encode_srgb_rgb(lin: [f64; 3]) -> [u8; 3] {
    let t = srgb_table();
    [t.encode(lin[0]), t.encode(lin[1]), t.encode(lin[2])]
}

impl SrgbTable {
    /// The code at the start of l's bucket; steps are further apart than a bucket is wide
    /// (they are densest near black, 1 / (255 x 12.92) apart: > 1 / BUCKETS), so at most one
    /// more lies before l. No loop and no branch: below 0 and NaN index the first bucket
    /// (code 0, as `linear_to_srgb` gives them), 1 and above the last (code 255), and the
    /// step after the last is NaN, which no value reaches.
    #[inline(always)]
    fn encode(&self, l: f64) -> u8 {
        let c = self.start[((l * BUCKETS as f64) as usize).min(BUCKETS - 1)] as usize;
        (c + (self.steps[c] <= l) as usize) as u8
    }
}

/// Buckets of the linear range [0, 1) in the encoder's index.
const BUCKETS: usize = 4096;

/// The encoder's tables: the code at each bucket's start, and the steps (with NaN after the
/// last).
struct SrgbTable {
    start: [u8; BUCKETS],
    steps: [f64; 256],
}

fn srgb_table() -> &'static SrgbTable {
    static TABLE: std::sync::LazyLock<SrgbTable> = std::sync::LazyLock::new(|| {
        let mut steps = [f64::NAN; 256];
        steps[..255].copy_from_slice(srgb_steps());
        let start = std::array::from_fn(|b| srgb_steps().partition_point(|&t| t <= b as f64 / BUCKETS as f64) as u8);
        SrgbTable { start, steps }
    });
    &TABLE
}

/// The linear values where [`linear_to_srgb`] steps from code k to k + 1.
fn srgb_steps() -> &'static [f64; 255] {
    static STEPS: std::sync::LazyLock<[f64; 255]> = std::sync::LazyLock::new(|| {
        let mut steps = [0.0; 255];
        for (k, step) in steps.iter_mut().enumerate() {
            // Smallest non-negative f64 (by bit pattern, which orders them) with code > k.
            let (mut lo, mut hi) = (0u64, 1f64.to_bits());
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                if linear_to_srgb(f64::from_bits(mid)) as usize > k {
                    hi = mid;
                } else {
                    lo = mid + 1;
                }
            }
            *step = f64::from_bits(lo);
        }
        steps
    });
    &STEPS
}

/// Linear albedo per kind, precomputed.
#[derive(Clone, Debug)]
pub struct Palette {
    lut: [f64; 256],
}

impl Default for Palette {
    fn default() -> Self {
        let mut lut = [0.0; 256];
        for (i, v) in lut.iter_mut().enumerate() {
            *v = srgb_to_linear(i as u8);
        }
        Palette { lut }
    }
}

impl Palette {
    /// Linear value of an sRGB code.
    pub fn linear(&self, c: u8) -> f64 {
        self.lut[c as usize]
    }

    pub fn albedo(&self, kind: Kind) -> [f64; 3] {
        let c = albedo_srgb(kind);
        [self.lut[c[0] as usize], self.lut[c[1] as usize], self.lut[c[2] as usize]]
    }
}

/// Irradiance [W/m2] that the fixed exposure renders as white: a white surface facing a
/// clear noon sun through glass is just below clipping.
pub const EXPOSURE: f64 = 1000.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip_and_ripe_is_red() {
        for c in 0..=255u8 {
            assert_eq!(linear_to_srgb(srgb_to_linear(c)), c);
        }
        let [r, g, b] = fruit_srgb(6);
        assert!(r as f64 > 3.0 * g as f64 && r > b);
        let [r, g, _] = fruit_srgb(1);
        assert!(g > r);
    }

    #[test]
    fn the_table_encoder_equals_the_curve() {
        let mut rng = agrisim_math::Rng::new(5);
        for _ in 0..200_000 {
            let l = rng.range(-0.1, 1.1);
            assert_eq!(encode_srgb(l), linear_to_srgb(l), "{l}");
        }
        // Around every step, to the last bit.
        for c in 0..=255u8 {
            let l = srgb_to_linear(c);
            for b in [l.to_bits().saturating_sub(2), l.to_bits(), l.to_bits() + 2] {
                let v = f64::from_bits(b);
                assert_eq!(encode_srgb(v), linear_to_srgb(v), "{v}");
            }
        }
        // At most one step inside any bucket (what the encoder's single increment relies on).
        for w in srgb_steps().windows(2) {
            assert!(w[1] - w[0] > 1.0 / BUCKETS as f64, "steps {} and {} closer than a bucket", w[0], w[1]);
        }
        // Each step is exactly where the curve steps (with the curve monotonic, the table
        // then equals it everywhere).
        for (k, &t) in srgb_steps().iter().enumerate() {
            assert_eq!(linear_to_srgb(t) as usize, k + 1, "step {k} at {t}");
            assert_eq!(linear_to_srgb(t.next_down()) as usize, k, "below step {k}");
        }
        assert_eq!(encode_srgb(f64::NAN), linear_to_srgb(f64::NAN));
        assert_eq!(encode_srgb(f64::INFINITY), 255);
        assert_eq!(encode_srgb(f64::NEG_INFINITY), 0);
        assert_eq!(encode_srgb(-0.0), 0);
        assert_eq!(encode_srgb_rgb([0.5, -1.0, 2.0]), [linear_to_srgb(0.5), 0, 255]);
    }
}
