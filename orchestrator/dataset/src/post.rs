//! Post-processing of the rendered colour image for the knobs the Camera FMU has no
//! parameter for: exposure and white balance (gains on linear light, then the sRGB curve
//! again, as a camera's ISP applies them), and a hue shift of each fruit's pixels (the
//! greenhouse has no fruit-colour key). The camera renders at a fixed exposure and neutral
//! white balance and encodes sRGB (IEC 61966-2-1).

/// sRGB code value (0-255) -> linear light in [0, 1].
fn to_linear(c: u8) -> f64 {
    let v = c as f64 / 255.0;
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light -> sRGB code value, clipped to [0, 255] (saturation, as a sensor clips).
fn to_srgb(l: f64) -> u8 {
    let l = l.clamp(0.0, 1.0);
    let v = if l <= 0.0031308 { 12.92 * l } else { 1.055 * l.powf(1.0 / 2.4) - 0.055 };
    (v * 255.0).round() as u8
}

/// Multiplies linear light by `2^ev * gains[c]` per channel, in place (a lookup table per
/// channel: the result depends on the code value alone).
pub fn exposure_white_balance(rgb: &mut [u8], ev: f64, gains: [f64; 3]) {
    let tables: [[u8; 256]; 3] =
        std::array::from_fn(|c| std::array::from_fn(|v| to_srgb(to_linear(v as u8) * ev.exp2() * gains[c])));
    for px in rgb.chunks_exact_mut(3) {
        for c in 0..3 {
            px[c] = tables[c][px[c] as usize];
        }
    }
}

/// Rotates the hue of one sRGB pixel by `degrees` about the grey axis (the chroma plane of
/// YIQ), keeping its luma; clipped to [0, 255].
pub fn rotate_hue(px: &mut [u8], degrees: f64) {
    let [r, g, b] = [px[0] as f64, px[1] as f64, px[2] as f64];
    let y = 0.299 * r + 0.587 * g + 0.114 * b;
    let i = 0.595716 * r - 0.274453 * g - 0.321263 * b;
    let q = 0.211456 * r - 0.522591 * g + 0.311135 * b;
    let (s, c) = degrees.to_radians().sin_cos();
    let (i, q) = (c * i - s * q, s * i + c * q);
    let back = [y + 0.9563 * i + 0.6210 * q, y - 0.2721 * i - 0.6474 * q, y - 1.1070 * i + 1.7046 * q];
    for (o, v) in px.iter_mut().zip(back) {
        *o = v.round().clamp(0.0, 255.0) as u8;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neutral_settings_change_nothing() {
        let mut rgb: Vec<u8> = (0..=255).flat_map(|v| [v, 255 - v, v / 2]).collect();
        let before = rgb.clone();
        exposure_white_balance(&mut rgb, 0.0, [1.0; 3]);
        assert_eq!(rgb, before);
        for px in rgb.chunks_exact_mut(3) {
            let was = px.to_vec();
            rotate_hue(px, 0.0);
            for (a, b) in px.iter().zip(&was) {
                assert!(a.abs_diff(*b) <= 1, "{was:?} -> {px:?}");
            }
        }
    }

    #[test]
    fn one_stop_doubles_linear_light_and_gains_act_per_channel() {
        let mut rgb = vec![100, 100, 100];
        exposure_white_balance(&mut rgb, 1.0, [1.0, 1.0, 0.5]);
        assert_eq!(rgb[0], to_srgb(2.0 * to_linear(100)));
        assert_eq!(rgb[2], 100);
        assert!(rgb[0] > 130);
        // A grey stays grey under a hue rotation; red turns toward yellow for +hue.
        let mut grey = [90, 90, 90];
        rotate_hue(&mut grey, 40.0);
        assert!(grey.iter().all(|&v| v.abs_diff(90) <= 1), "{grey:?}");
        let mut red = [200, 30, 20];
        rotate_hue(&mut red, -20.0);
        let mut red2 = [200, 30, 20];
        rotate_hue(&mut red2, 20.0);
        assert_ne!(red, red2);
        assert!(red.iter().zip(red2).any(|(a, b)| a.abs_diff(b) > 10));
    }
}
