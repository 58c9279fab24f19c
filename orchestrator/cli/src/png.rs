//! PNG output (8-bit RGB) for the pictures `agrisim snapshot` writes, via the `png` crate.

/// Encodes `rgb` (row-major, 3 bytes a pixel) as a PNG file's bytes.
pub fn encode_rgb(width: u32, height: u32, rgb: &[u8]) -> Vec<u8> {
    assert_eq!(rgb.len(), width as usize * height as usize * 3, "RGB buffer size");
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    // Writing to memory with a buffer of the checked size cannot fail.
    let mut w = enc.write_header().expect("PNG header to memory");
    w.write_image_data(rgb).expect("PNG data to memory");
    w.finish().expect("PNG end to memory");
    out
}

/// A perceptual colour map (blue -> green -> yellow -> red) for t in [0, 1].
pub fn colormap(t: f64) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    let stops =
        [[48.0, 18.0, 59.0], [40.0, 150.0, 220.0], [60.0, 200.0, 90.0], [250.0, 220.0, 40.0], [200.0, 30.0, 20.0]];
    let x = t * (stops.len() - 1) as f64;
    let i = (x.floor() as usize).min(stops.len() - 2);
    let f = x - i as f64;
    std::array::from_fn(|c| (stops[i][c] + (stops[i + 1][c] - stops[i][c]) * f).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Decodes with the png crate: (width, height, RGB bytes).
    fn decode(bytes: &[u8]) -> (u32, u32, Vec<u8>) {
        let mut r = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().unwrap();
        let mut buf = vec![0; r.output_buffer_size().unwrap()];
        let info = r.next_frame(&mut buf).unwrap();
        assert_eq!((info.color_type, info.bit_depth), (png::ColorType::Rgb, png::BitDepth::Eight));
        buf.truncate(info.buffer_size());
        (info.width, info.height, buf)
    }

    #[test]
    fn round_trips_size_and_pixels() {
        let rgb = [255, 0, 0, 0, 255, 0];
        assert_eq!(decode(&encode_rgb(2, 1, &rgb)), (2, 1, rgb.to_vec()));

        let (w, h) = (7, 5);
        let rgb: Vec<u8> = (0..w * h).flat_map(|i| colormap(i as f64 / (w * h - 1) as f64)).collect();
        assert_eq!(decode(&encode_rgb(w, h, &rgb)), (w, h, rgb));
    }

    #[test]
    #[should_panic(expected = "RGB buffer size")]
    fn wrong_buffer_size_panics() {
        encode_rgb(2, 2, &[0; 6]);
    }
}
