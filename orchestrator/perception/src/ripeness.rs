//! Ripeness as the USDA defines it: by the fraction of the fruit's surface that is coloured
//! (United States Standards for Grades of Fresh Tomatoes, 7 CFR 51.1860: breakers a break in
//! colour on at most 10 % of the surface, turning 10-30 %, pink more than 30 % pink or red,
//! light red more than 60 % pinkish-red or red, red more than 90 % red), not by how much of
//! the image is red: a pink fruit seen from below shows mostly its coloured blossom end.
//!
//! The break starts at the blossom end (the bottom) and moves up, so the coloured part is a
//! cap from the bottom to a front. By Archimedes' hat-box theorem the area of a sphere's zone
//! is proportional to its height, so the fraction of the surface below height z is
//! (z / r + 1) / 2, linear in height: each skin pixel's 3-D point gives the fraction of the
//! surface below it ([`surface_below`]), and the front is the fraction that best separates
//! coloured pixels below from green ones above ([`fit_front`]). Two fronts are fitted: of any
//! break from green, and of pink or red. The stages follow from them ([`stage_shares`]).
//! The calyx, green and on top, is "green above" and does not move a front below it; it
//! stops a red fruit's front near 0.9, so light red is told from red by the hue of the
//! pink-or-red skin. Skin is every pixel on the fruit's fitted sphere, so the heights are
//! the sphere's, along the world's up (from TF): a camera tilted or below the fruit reads
//! the same front.

use crate::colour::{hsv_hue, stage_of_hue, HUE_BOUNDS};

/// Upper coloured fraction of stages 1-5 (7 CFR 51.1860): green none, breakers 10 %, turning
/// 30 %, pink 60 %, light red 90 %.
pub const STAGE_FRACTIONS: [f64; 5] = [0.0, 0.10, 0.30, 0.60, 0.90];

/// A break from green: HSV hue below this [deg]. Green skin is about 80-92 deg, the colour
/// at a pink or red front's edge 17-25 deg, a turning one's 41 deg; a blend half-way between
/// green and those edges (in linear light, as light mixes at a blurred front) has a hue of
/// 38-55 deg, so the front found is where the skin is half changed.
pub const BREAK_HUE: f64 = HUE_BOUNDS[3];

/// Pink or red (USDA's colours of stages 4-6): HSV hue below the pink / turning bound.
pub const PINK_HUE: f64 = HUE_BOUNDS[2];

/// Pixels less saturated than this (HSV) tell no skin colour: a highlight shows the light's
/// colour, not the skin's.
pub const MIN_SATURATION: f64 = 0.15;

/// Fewest telling skin pixels for a front.
pub const MIN_PIXELS: usize = 20;

/// Least spread of a front [surface fraction]: the hat-box measure is exact for a sphere,
/// and a tomato of shape index 0.85-0.90 (slightly flattened) seen as its fitted sphere
/// reads heights about a tenth short of its poles (a fraction of 0.6 as 0.59); a blurred
/// front is located within a few hundredths.
pub const MIN_SPREAD: f64 = 0.02;

/// Fraction of a sphere's surface (centre `c`, radius `r`) below the height of `p` along the
/// unit vector `up`: (h / r + 1) / 2 (Archimedes' hat-box theorem), clamped to 0..1.
pub fn surface_below(p: [f64; 3], c: [f64; 3], r: f64, up: [f64; 3]) -> f64 {
    let h = (p[0] - c[0]) * up[0] + (p[1] - c[1]) * up[1] + (p[2] - c[2]) * up[2];
    0.5 * (h / r).clamp(-1.0, 1.0) + 0.5
}

/// What a skin pixel tells: its HSV hue, or `None` (grey or a highlight). Hues past 300 deg
/// are reds below 0.
pub fn skin_hue(rgb: [u8; 3]) -> Option<f64> {
    let max = rgb.iter().copied().max().unwrap_or(0) as f64;
    let min = rgb.iter().copied().min().unwrap_or(0) as f64;
    if max <= 0.0 || (max - min) / max < MIN_SATURATION {
        return None;
    }
    hsv_hue(rgb).map(|h| if h >= 300.0 { h - 360.0 } else { h })
}

/// A fitted front: the coloured fraction of the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Front {
    /// The coloured fraction: the lowest front of least misclassified pixels (the cautious
    /// end when several fit as well).
    pub fraction: f64,
    /// The highest front of least misclassified pixels: 1 when every pixel up to the highest
    /// seen is coloured (the fruit's top not seen coloured or green: `fraction` is then only
    /// a lower bound).
    pub upper: f64,
    /// How far the front may lie [surface fraction]: half the span of the fronts that
    /// misclassify at most one Poisson standard deviation (the square root of the least
    /// count, at least one pixel) more than the best, as counts of misclassified pixels
    /// fluctuate; for an open front, how far below it such fronts reach. A wavy or blurred
    /// front gives a wide span, a few stray pixels far from it (a leaf's edge on the sphere,
    /// the blossom-end scar) add to every front alike and do not.
    pub spread: f64,
    /// Pixels fitted, and misclassified.
    pub pixels: usize,
    pub misfit: usize,
}

impl Front {
    /// The front is only a lower bound: the highest skin seen is coloured.
    pub fn open(&self) -> bool {
        self.upper >= 1.0
    }
}

/// Fits a front to skin pixels given as (fraction of the surface below, coloured): the
/// threshold t minimising coloured pixels above t plus green ones below (each interval
/// between neighbouring samples is one candidate, placed at its middle; none below the lowest
/// pixel when it is green: 0; at the highest pixel when all are coloured). `None` for fewer
/// than [`MIN_PIXELS`].
pub fn fit_front(samples: &mut [(f64, bool)]) -> Option<Front> {
    let n = samples.len();
    if n < MIN_PIXELS {
        return None;
    }
    // Unstable is enough: samples equal in both keys are the same value.
    samples.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    // errors[k]: green among the k lowest + coloured among the others.
    let mut errors = vec![samples.iter().filter(|s| s.1).count(); n + 1];
    for k in 1..=n {
        errors[k] = if samples[k - 1].1 { errors[k - 1] - 1 } else { errors[k - 1] + 1 };
    }
    let best = errors.iter().copied().min().unwrap_or(0);
    let k_lo = errors.iter().position(|&e| e == best).unwrap_or(0);
    let k_hi = errors.iter().rposition(|&e| e == best).unwrap_or(0);
    // Fronts between samples k - 1 and k: (lowest, highest) of them.
    let span = |k: usize| match k {
        0 => (0.0, samples[0].0),
        k if k == n => (samples[n - 1].0, 1.0),
        k => {
            let mid = 0.5 * (samples[k - 1].0 + samples[k].0);
            (mid, mid)
        }
    };
    let fraction = span(k_lo).0;
    let upper = span(k_hi).1;
    let near = best + ((best as f64).sqrt().ceil() as usize).max(1);
    let a = span(errors.iter().position(|&e| e <= near).unwrap_or(k_lo)).0;
    let b = span(errors.iter().rposition(|&e| e <= near).unwrap_or(k_hi)).1;
    let spread = if upper >= 1.0 { fraction - a } else { 0.5 * (b - a) };
    Some(Front { fraction, upper, spread, pixels: n, misfit: best })
}

/// P(X <= x) for X normal(mean, sd), by the complementary error function (Abramowitz and
/// Stegun 7.1.26, error below 1.5e-7).
fn normal_cdf(x: f64, mean: f64, sd: f64) -> f64 {
    let z = (x - mean) / (sd * std::f64::consts::SQRT_2);
    let t = 1.0 / (1.0 + 0.327_591_1 * z.abs());
    let poly =
        t * (0.254_829_592 + t * (-0.284_496_736 + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erf = 1.0 - poly * (-z * z).exp();
    0.5 * (1.0 + if z >= 0.0 { erf } else { -erf })
}

/// The ripeness a segment's skin shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ripeness {
    /// Front of any break from green.
    pub any: Front,
    /// Front of pink or red, if any pixel is.
    pub pink: Front,
    /// Share of the pink or red pixels whose hue is red's (stage 6), splitting light red
    /// from red.
    pub red_share: f64,
}

/// The ripeness of skin pixels given as (fraction of the surface below, sRGB); `None` when
/// fewer than [`MIN_PIXELS`] tell a colour.
pub fn ripeness(pixels: impl IntoIterator<Item = (f64, [u8; 3])>) -> Option<Ripeness> {
    let mut any = vec![];
    let mut pink = vec![];
    let (mut n_pink, mut n_red) = (0usize, 0usize);
    for (b, rgb) in pixels {
        let Some(h) = skin_hue(rgb) else { continue };
        let is_pink = h < PINK_HUE;
        any.push((b, h < BREAK_HUE));
        pink.push((b, is_pink));
        if is_pink {
            n_pink += 1;
            if stage_of_hue(h.rem_euclid(360.0)) == 6 {
                n_red += 1;
            }
        }
    }
    let any = fit_front(&mut any)?;
    let pink = fit_front(&mut pink)?;
    let red_share = if n_pink > 0 { n_red as f64 / n_pink as f64 } else { 0.0 };
    Some(Ripeness { any, pink, red_share })
}

/// Probabilities of stages 1-6 (index 0 = stage 1; they sum to 1): each front a normal
/// about its fraction with its spread (at least [`MIN_SPREAD`]); stages 4 and up by the
/// pink-or-red front against 30 % and 60 %, stages 1-3 by the break's front against 0 and
/// 10 %; the ripe share split between light red and red by `red_share`. An open front (only
/// a lower bound, the top not seen) stands at its bound, so a fruit is never called riper
/// than the skin seen shows.
pub fn stage_shares(r: &Ripeness) -> [f64; 6] {
    let cdf = |f: &Front, x: f64| normal_cdf(x, f.fraction, f.spread.max(MIN_SPREAD));
    let p = &r.pink;
    let ripe = 1.0 - cdf(p, STAGE_FRACTIONS[3]);
    let pink = cdf(p, STAGE_FRACTIONS[3]) - cdf(p, STAGE_FRACTIONS[2]);
    let below_pink = cdf(p, STAGE_FRACTIONS[2]);
    let a = &r.any;
    let green = cdf(a, STAGE_FRACTIONS[0]);
    let breaker = cdf(a, STAGE_FRACTIONS[1]) - green;
    let turning = 1.0 - cdf(a, STAGE_FRACTIONS[1]);
    [
        below_pink * green,
        below_pink * breaker,
        below_pink * turning,
        pink,
        ripe * (1.0 - r.red_share),
        ripe * r.red_share,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Unit vector.
    fn unit(v: [f64; 3]) -> [f64; 3] {
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|x| x / n)
    }

    /// The visible points of a sphere (centre origin, radius 1) seen from direction `eye`
    /// (unit, from the centre to the camera, far away): a Fibonacci lattice over the sphere
    /// (equal area per point), kept where the surface faces the eye, weighted by how much
    /// image area it takes (its cosine to the view: points are sampled `ceil(4 cos)` times).
    fn seen(eye: [f64; 3], n: usize) -> Vec<[f64; 3]> {
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        let mut out = vec![];
        for i in 0..n {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let rho = (1.0 - z * z).sqrt();
            let phi = golden * i as f64;
            let p = [rho * phi.cos(), rho * phi.sin(), z];
            let c = p[0] * eye[0] + p[1] * eye[1] + p[2] * eye[2];
            if c > 0.05 {
                for _ in 0..(4.0 * c).ceil() as usize {
                    out.push(p);
                }
            }
        }
        out
    }

    /// Colour of a synthetic fruit coloured from the bottom up to `fraction` of its surface
    /// (z up): red-pink below the front (a red fruit's deep red far below it), leaf-green
    /// above, a wavy front as on real fruit.
    fn skin(p: [f64; 3], fraction: f64) -> [u8; 3] {
        let below = 0.5 * (p[2] + 1.0);
        let wave = 0.04 * (3.0 * p[1].atan2(p[0])).sin();
        if below < fraction + wave {
            if fraction > 0.9 {
                [185, 28, 20]
            } else {
                [228, 100, 80]
            }
        } else {
            [120, 160, 62]
        }
    }

    /// Spheres coloured up to a known fraction, seen level, from 45 deg below and 45 deg
    /// above: the fraction within a few hundredths and the stage right; the hue share of the
    /// same pixels (what the stage was before) calls the pink fruit seen from below ripe.
    #[test]
    fn the_coloured_fraction_from_below_level_and_above() {
        let views = [("level", [1.0, 0.0, 0.0]), ("below", [1.0, 0.0, -1.0]), ("above", [1.0, 0.0, 1.0])];
        for (fraction, stage) in [(0.2, 3u8), (0.45, 4), (0.55, 4), (0.7, 5), (0.97, 6)] {
            for (name, eye) in views {
                let pts = seen(unit(eye), 4000);
                let px: Vec<(f64, [u8; 3])> = pts
                    .iter()
                    .map(|&p| (surface_below(p, [0.0; 3], 1.0, [0.0, 0.0, 1.0]), skin(p, fraction)))
                    .collect();
                let r = ripeness(px.iter().copied()).expect("enough pixels");
                let shares = stage_shares(&r);
                let (best, _) = crate::colour::classify(&shares);
                let front = if stage >= 4 { r.pink } else { r.any };
                if !front.open() {
                    assert!((front.fraction - fraction).abs() < 0.04, "{fraction} {name}: {r:?}");
                }
                if stage == 6 && name == "below" {
                    // The top of a red fruit is not seen from below: a lower bound, ripe.
                    assert!(front.open() && front.fraction > 0.6, "{r:?}");
                }
                assert_eq!(best, stage, "{fraction} {name}: {shares:?} {r:?}");
                assert!((shares.iter().sum::<f64>() - 1.0).abs() < 1e-9, "{shares:?}");
                if fraction == 0.45 && name == "below" {
                    // What hue votes said: most pixels are light red's hue.
                    let votes = crate::colour::stage_votes(px.iter().map(|p| p.1));
                    assert!(votes[4] + votes[5] > 0.5, "{votes:?}");
                    assert!(shares[4] + shares[5] < 0.05, "{shares:?}");
                }
            }
        }
    }

    /// The front fit: a clean step, a step with no green seen (open), and ties deterministic.
    #[test]
    fn the_front_fit() {
        let mut s: Vec<(f64, bool)> = (0..40).map(|i| (i as f64 / 40.0, i < 18)).collect();
        let f = fit_front(&mut s).unwrap();
        assert!((f.fraction - 0.4375).abs() < 1e-12 && f.upper == f.fraction && f.misfit == 0, "{f:?}");
        assert!((f.spread - 0.025).abs() < 1e-12, "{f:?}");
        // Stray green pixels far below the front (a leaf's edge on the sphere): the same front,
        // and its spread stays that of the front.
        let step = (0..400).map(|i| ((i as f64 + 0.5) / 400.0, i < 200));
        let mut stray: Vec<(f64, bool)> = step.chain((0..5).map(|i| (0.01 * i as f64, false))).collect();
        let g = fit_front(&mut stray).unwrap();
        assert!(g.fraction == 0.5 && g.misfit == 5 && g.spread < 0.01, "{g:?}");
        let mut s: Vec<(f64, bool)> = (0..40).map(|i| (0.2 + i as f64 / 100.0, true)).collect();
        let f = fit_front(&mut s).unwrap();
        assert!(f.open() && (f.fraction - 0.59).abs() < 1e-12, "{f:?}");
        let mut s: Vec<(f64, bool)> = (0..40).map(|i| (0.5 + i as f64 / 100.0, false)).collect();
        let f = fit_front(&mut s).unwrap();
        assert!(f.fraction == 0.0 && !f.open(), "{f:?}");
        assert!((f.upper - 0.5).abs() < 1e-12, "{f:?}");
        // A green pixel, then a coloured one, at the front: two equally good fronts, the
        // lower kept.
        let mut s: Vec<(f64, bool)> = (0..40).map(|i| (i as f64 / 40.0, i < 10 || i == 11)).collect();
        let f = fit_front(&mut s).unwrap();
        assert!((f.fraction - 0.2375).abs() < 1e-12 && (f.upper - 0.2875).abs() < 1e-12 && f.misfit == 1, "{f:?}");
        assert!(fit_front(&mut s[..MIN_PIXELS - 1]).is_none());
        assert!((normal_cdf(1.0, 0.0, 1.0) - 0.841_344_746).abs() < 1e-6);
        assert!((surface_below([0.0, -0.5, 0.0], [0.0; 3], 1.0, [0.0, -1.0, 0.0]) - 0.75).abs() < 1e-12);
    }
}
