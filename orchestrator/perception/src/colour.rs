//! Colour: which pixels may be tomato (CIELAB: chroma and hue angle, so a segment does not
//! depend on one exact colour or on the exposure) and which USDA colour class a pixel of
//! skin shows (the HSV hue of its sRGB pixels; CIELAB's hue angle puts light red and red at
//! the same angle, HSV's separates them, and a common scale of the three channels, as light
//! and shadow give, leaves it unchanged). A fruit's stage is read from how much of its
//! surface shows which class ([`crate::ripeness`]), not from its pixels' votes alone.

/// The six USDA ripeness stages ("United States Standards for Grades of Fresh Tomatoes",
/// colour classification), as `vision_msgs` class ids.
pub const STAGES: [&str; 6] = ["green", "breaker", "turning", "pink", "light_red", "red"];

/// The USDA stage (1..=6) of a class id, if it is one of [`STAGES`].
pub fn stage_of(class_id: &str) -> Option<u8> {
    STAGES.iter().position(|s| *s == class_id).map(|i| i as u8 + 1)
}

/// Stages 5 and 6 are ripe for harvest (the harvest benchmark's rule).
pub fn is_ripe(stage: u8) -> bool {
    stage >= 5
}

fn linear(c: u8) -> f64 {
    let c = c as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// sRGB -> linear, by table.
pub struct Linearize([f32; 256]);

impl Default for Linearize {
    fn default() -> Self {
        let mut t = [0.0f32; 256];
        for (i, v) in t.iter_mut().enumerate() {
            *v = linear(i as u8) as f32;
        }
        Linearize(t)
    }
}

impl Linearize {
    /// Linear value of one sRGB channel.
    pub fn channel(&self, c: u8) -> f32 {
        self.0[c as usize]
    }

    /// CIELAB (D65 white) of an sRGB pixel: (L*, a*, b*).
    pub fn lab(&self, rgb: [u8; 3]) -> [f32; 3] {
        let [r, g, b] = rgb.map(|c| self.0[c as usize]);
        let x = (0.412_456_4 * r + 0.357_576_1 * g + 0.180_437_5 * b) / 0.950_47;
        let y = 0.212_672_9 * r + 0.715_152_2 * g + 0.072_175 * b;
        let z = (0.019_333_9 * r + 0.119_192 * g + 0.950_304_1 * b) / 1.088_83;
        let f = |t: f32| if t > 216.0 / 24389.0 { t.cbrt() } else { (24389.0 / 27.0 * t + 16.0) / 116.0 };
        let (fx, fy, fz) = (f(x), f(y), f(z));
        [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
    }
}

/// Which pixels may be tomato: saturated colour from red through orange and yellow, not the
/// yellow-green to blue-green of stems and leaves, not the greys of the structure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FruitColour {
    /// Least CIELAB chroma.
    pub min_chroma: f32,
    /// Least chroma per unit of lightness (greys and the sky are below it at any exposure).
    pub min_chroma_per_l: f32,
    /// Largest CIELAB hue angle [deg] (red is about 40, a breaker's yellow about 108,
    /// stems about 124, leaves 133).
    pub max_hue: f32,
    /// Hues above this angle [deg] wrap to red (magenta-red).
    pub wrap_hue: f32,
}

impl Default for FruitColour {
    fn default() -> Self {
        FruitColour { min_chroma: 8.0, min_chroma_per_l: 0.4, max_hue: 116.0, wrap_hue: 340.0 }
    }
}

impl FruitColour {
    pub fn accepts(&self, lab: [f32; 3]) -> bool {
        let [l, a, b] = lab;
        let chroma = a.hypot(b);
        if chroma < self.min_chroma || chroma < self.min_chroma_per_l * l.max(1.0) {
            return false;
        }
        let h = b.atan2(a).to_degrees();
        let h = if h < 0.0 { h + 360.0 } else { h };
        h <= self.max_hue || h >= self.wrap_hue
    }
}

/// HSV hue of an sRGB pixel [deg, 0..360); `None` for a grey.
pub fn hsv_hue(rgb: [u8; 3]) -> Option<f64> {
    let [r, g, b] = rgb.map(f64::from);
    let max = r.max(g).max(b);
    let d = max - r.min(g).min(b);
    if d <= 0.0 {
        return None;
    }
    let h = if max == r {
        60.0 * ((g - b) / d)
    } else if max == g {
        60.0 * ((b - r) / d) + 120.0
    } else {
        60.0 * ((r - g) / d) + 240.0
    };
    Some(if h < 0.0 { h + 360.0 } else { h })
}

/// Upper HSV hue [deg] of stages 6, 5, 4, 3, 2 (stage 1 above the last): midpoints between
/// reference hues of the USDA colour classes under white light (red about 2, light red 7,
/// pink 14, turning 36, breaker 65, green 92).
pub const HUE_BOUNDS: [f64; 5] = [4.5, 10.3, 25.0, 50.0, 78.0];

/// The USDA stage (1..=6) of one HSV hue. Hues past 300 deg are reds below 0.
pub fn stage_of_hue(h: f64) -> u8 {
    let h = if h >= 300.0 { h - 360.0 } else { h };
    match HUE_BOUNDS.iter().position(|&b| h < b) {
        Some(i) => 6 - i as u8,
        None => 1,
    }
}

/// Votes of a segment's pixels for each stage: fractions summing to 1 (index 0 = stage 1).
pub fn stage_votes(pixels: impl IntoIterator<Item = [u8; 3]>) -> [f64; 6] {
    let mut n = [0u32; 6];
    for p in pixels {
        if let Some(h) = hsv_hue(p) {
            n[stage_of_hue(h) as usize - 1] += 1;
        }
    }
    let total: u32 = n.iter().sum();
    if total == 0 {
        return [0.0; 6];
    }
    n.map(|k| k as f64 / total as f64)
}

/// The stage with the most votes (1..=6) and its share; ties go to the riper stage.
pub fn classify(votes: &[f64; 6]) -> (u8, f64) {
    let mut best = (1u8, votes[0]);
    for (i, &v) in votes.iter().enumerate().skip(1) {
        if v >= best.1 {
            best = (i as u8 + 1, v);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scaled(rgb: [u8; 3], k: f64) -> [u8; 3] {
        // Scale in linear light (a shadow or dusk), back to sRGB.
        rgb.map(|c| {
            let l = (linear(c) * k).clamp(0.0, 1.0);
            let s = if l <= 0.0031308 { 12.92 * l } else { 1.055 * l.powf(1.0 / 2.4) - 0.055 };
            (s * 255.0).round() as u8
        })
    }

    /// Synthetic colours of each stage (not the camera's table: a spread around each class)
    /// classify as their stage, lit fully and at a quarter of the light.
    #[test]
    fn synthetic_stage_colours_classify() {
        let cases: [([u8; 3], u8); 12] = [
            ([195, 22, 18], 6),
            ([170, 20, 25], 6),
            ([225, 72, 45], 5),
            ([235, 60, 35], 5),
            ([230, 110, 80], 4),
            ([220, 125, 95], 4),
            ([210, 150, 60], 3),
            ([200, 140, 70], 3),
            ([165, 170, 60], 2),
            ([190, 185, 80], 2),
            ([90, 145, 45], 1),
            ([100, 150, 60], 1),
        ];
        for (rgb, stage) in cases {
            for k in [1.0, 0.25] {
                let c = scaled(rgb, k);
                let h = hsv_hue(c).unwrap();
                assert_eq!(stage_of_hue(h), stage, "{rgb:?} x{k} -> {c:?}, hue {h:.1}");
            }
        }
    }

    #[test]
    fn the_mask_takes_fruit_colours_and_refuses_foliage_and_greys() {
        let lin = Linearize::default();
        let m = FruitColour::default();
        for fruit in [[195, 22, 18], [225, 72, 45], [230, 110, 80], [210, 150, 60], [165, 170, 60], [60, 8, 6]] {
            assert!(m.accepts(lin.lab(fruit)), "{fruit:?}");
        }
        for other in [[58, 112, 38], [96, 128, 52], [150, 145, 135], [190, 205, 212], [170, 200, 235], [228, 228, 228]]
        {
            assert!(!m.accepts(lin.lab(other)), "{other:?}");
        }
    }

    #[test]
    fn votes_and_the_winner() {
        let px = vec![[195, 22, 18]; 7].into_iter().chain(vec![[225, 72, 45]; 3]).chain([[128, 128, 128]]);
        let v = stage_votes(px);
        assert!((v[5] - 0.7).abs() < 1e-12 && (v[4] - 0.3).abs() < 1e-12, "{v:?}");
        assert_eq!(classify(&v), (6, v[5]));
        assert_eq!(stage_votes(std::iter::empty()), [0.0; 6]);
        assert_eq!(stage_of("light_red"), Some(5));
        assert_eq!(stage_of("blue"), None);
    }
}
