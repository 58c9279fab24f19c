//! PNG files the dataset writes: 8-bit RGB and 16-bit grey (depth in mm, instance indices).

fn encode(width: u32, height: u32, color: png::ColorType, depth: png::BitDepth, data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, width, height);
    enc.set_color(color);
    enc.set_depth(depth);
    // To memory, with the buffer size checked by the callers: cannot fail.
    let mut w = enc.write_header().expect("PNG header to memory");
    w.write_image_data(data).expect("PNG data to memory");
    w.finish().expect("PNG end to memory");
    out
}

/// 8-bit RGB, row-major.
pub fn rgb8(width: u32, height: u32, rgb: &[u8]) -> Vec<u8> {
    assert_eq!(rgb.len(), width as usize * height as usize * 3, "RGB buffer size");
    encode(width, height, png::ColorType::Rgb, png::BitDepth::Eight, rgb)
}

/// 16-bit grey, row-major (PNG stores the samples big-endian).
pub fn grey16(width: u32, height: u32, values: &[u16]) -> Vec<u8> {
    assert_eq!(values.len(), width as usize * height as usize, "grey buffer size");
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_be_bytes()).collect();
    encode(width, height, png::ColorType::Grayscale, png::BitDepth::Sixteen, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sixteen_bit_grey_round_trips() {
        let v: Vec<u16> = (0..12).map(|i| i * 5000 + 7).collect();
        let bytes = grey16(4, 3, &v);
        let mut r = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().unwrap();
        let mut buf = vec![0; r.output_buffer_size().unwrap()];
        let info = r.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height, info.bit_depth), (4, 3, png::BitDepth::Sixteen));
        let back: Vec<u16> =
            buf[..info.buffer_size()].chunks_exact(2).map(|b| u16::from_be_bytes([b[0], b[1]])).collect();
        assert_eq!(back, v);
    }
}
