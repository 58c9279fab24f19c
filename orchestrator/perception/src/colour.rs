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
    /// Least CIELAB chroma in a frame exposed at least as [`Self::exposure_reference`].
    pub min_chroma: f32,
    /// Least chroma per unit of lightness (greys and the sky are below it at any exposure).
    pub min_chroma_per_l: f32,
    /// Largest CIELAB hue angle [deg] (red is about 40, a breaker's yellow about 108,
    /// stems about 124, leaves 133).
    pub max_hue: f32,
    /// Hues above this angle [deg] wrap to red (magenta-red).
    pub wrap_hue: f32,
    /// The frame exposure ([`exposure_lightness`]) down to which `min_chroma` holds. Daylight
    /// frames of the crop expose at L* 46-53 (overcast, noon); at dusk 17, where a red fruit
    /// in shadow keeps a chroma of 6-10 and `min_chroma` alone cut it to fragments.
    pub exposure_reference: f32,
}

impl Default for FruitColour {
    fn default() -> Self {
        FruitColour {
            min_chroma: 8.0,
            min_chroma_per_l: 0.4,
            max_hue: 116.0,
            wrap_hue: 340.0,
            exposure_reference: 40.0,
        }
    }
}

/// CIELAB lightness L* of a relative luminance Y (D65 white = 1).
fn lightness(y: f64) -> f64 {
    if y > 216.0 / 24389.0 {
        116.0 * y.cbrt() - 16.0
    } else {
        24389.0 / 27.0 * y
    }
}

/// Relative luminance Y of a CIELAB lightness L* (the inverse of [`lightness`]).
fn luminance(l: f64) -> f64 {
    if l > 8.0 {
        ((l + 16.0) / 116.0).powi(3)
    } else {
        l * 27.0 / 24389.0
    }
}

/// Rec. 709 luma of an sRGB pixel, 0..=255 (weights x 256: 54, 183, 19).
pub fn luma(rgb: [u8; 3]) -> u8 {
    ((54 * rgb[0] as u32 + 183 * rgb[1] as u32 + 19 * rgb[2] as u32) >> 8) as u8
}

/// A frame's exposure: the lightness L* of its bright surfaces, the 90th percentile of the
/// luma histogram of its pixels (read as the sRGB value of a grey). A percentile, not the
/// mean, so that how much shadow or sky a view holds moves it little.
pub fn exposure_lightness(histogram: &[u32; 256]) -> f32 {
    let total: u64 = histogram.iter().map(|&n| n as u64).sum();
    if total == 0 {
        return 0.0;
    }
    let want = (total * 9).div_ceil(10);
    let mut seen = 0u64;
    for (v, &n) in histogram.iter().enumerate() {
        seen += n as u64;
        if seen >= want {
            return lightness(linear(v as u8)) as f32;
        }
    }
    100.0
}

/// Chroma floors are kept in steps of this (the detector memoizes each colour's chroma in
/// these steps, so a floor in them compares exactly).
pub const CHROMA_STEP: f32 = 0.25;

impl FruitColour {
    /// Whether a pixel of CIELAB `lab` may be tomato in a frame of exposure `exposure`
    /// ([`exposure_lightness`]).
    pub fn accepts(&self, lab: [f32; 3], exposure: f32) -> bool {
        self.chroma_if_hue(lab).is_some_and(|c| c >= self.chroma_floor(exposure))
    }

    /// The pixel's chroma if its hue and its chroma per lightness may be tomato; the chroma
    /// floor ([`Self::chroma_floor`]) is the test left.
    pub fn chroma_if_hue(&self, lab: [f32; 3]) -> Option<f32> {
        let [l, a, b] = lab;
        let chroma = a.hypot(b);
        if chroma < self.min_chroma_per_l * l.max(1.0) {
            return None;
        }
        let h = b.atan2(a).to_degrees();
        let h = if h < 0.0 { h + 360.0 } else { h };
        (h <= self.max_hue || h >= self.wrap_hue).then_some(chroma)
    }

    /// The least chroma in a frame of exposure `exposure` (L*), in steps of [`CHROMA_STEP`].
    /// Under k times less light a colour's a* and b* shrink as its lightness does (by the
    /// cube root of k, (L* + 16) / (L*ref + 16), above L* 8), so the floor shrinks with the
    /// frame's exposure below [`Self::exposure_reference`], to a quarter at most.
    pub fn chroma_floor(&self, exposure: f32) -> f32 {
        let reference = self.exposure_reference as f64;
        let k = if exposure as f64 >= reference {
            1.0
        } else {
            (luminance(exposure.max(0.0) as f64) / luminance(reference)).cbrt().max(0.25)
        };
        let floor = self.min_chroma * k as f32;
        (floor / CHROMA_STEP).floor() * CHROMA_STEP
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
            assert!(m.accepts(lin.lab(fruit), 50.0), "{fruit:?}");
        }
        for other in [[58, 112, 38], [96, 128, 52], [150, 145, 135], [190, 205, 212], [170, 200, 235], [228, 228, 228]]
        {
            assert!(!m.accepts(lin.lab(other), 50.0), "{other:?}");
        }
    }

    /// The chroma floor holds in daylight and falls with the frame's exposure as a colour's
    /// chroma does, in exact steps, to a quarter at most; the exposure is the luma
    /// histogram's 90th percentile as L*.
    #[test]
    fn the_chroma_floor_follows_the_exposure() {
        let m = FruitColour::default();
        for e in [40.0, 46.0, 53.0, 100.0] {
            assert_eq!(m.chroma_floor(e), m.min_chroma);
        }
        // L* 12.3 (a wall at dusk): (12.3 + 16) / (40 + 16) of 8, down to a step.
        assert_eq!(m.chroma_floor(12.3), 4.0);
        assert_eq!(m.chroma_floor(0.0), 2.0);
        let mut last = m.min_chroma;
        for e in (0..=40).rev().map(|e| e as f32) {
            let f = m.chroma_floor(e);
            assert!(f <= last && f >= 2.0 && (f / CHROMA_STEP).fract() == 0.0, "{e} -> {f}");
            last = f;
        }
        // A colour scaled darker keeps its hue and loses chroma at about the floor's rate.
        let lin = Linearize::default();
        let red = [195, 22, 18];
        let (bright, dim) = (lin.lab(red), lin.lab(scaled(red, 0.2)));
        let chroma = |l: [f32; 3]| l[1].hypot(l[2]);
        let rate = chroma(dim) / chroma(bright);
        let floor_rate = m.chroma_floor(lightness(luminance(40.0) * 0.2) as f32) / m.min_chroma;
        assert!((rate - floor_rate).abs() < 0.08, "{rate} vs {floor_rate}");
        // The exposure: 90 % of 1000 pixels at luma 30 or below, the rest at 200.
        let mut hist = [0u32; 256];
        hist[30] = 900;
        hist[200] = 100;
        assert!((exposure_lightness(&hist) - lightness(linear(30)) as f32).abs() < 1e-4);
        hist[30] = 899;
        hist[31] = 1;
        assert!((exposure_lightness(&hist) - lightness(linear(31)) as f32).abs() < 1e-4);
        assert_eq!(exposure_lightness(&[0; 256]), 0.0);
        assert_eq!(luma([255, 255, 255]), 255);
        assert_eq!(luma([0, 0, 0]), 0);
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
