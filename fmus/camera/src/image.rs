//! Frames as sensor_msgs/Image: rgb8, 32FC1 (depth, m) and 32SC1 (labels), little-endian.

use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::sensor_msgs::Image;
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::Message;

fn image(
    stamp_ns: i64,
    frame_id: &str,
    width: u32,
    height: u32,
    encoding: &str,
    bytes_per_px: u32,
    data: Vec<u8>,
) -> Image {
    Image {
        header: Header::new(Time::from_nanos(stamp_ns), frame_id),
        height,
        width,
        encoding: encoding.into(),
        is_bigendian: 0,
        step: width * bytes_per_px,
        data,
    }
}

pub fn rgb8(stamp_ns: i64, frame_id: &str, width: u32, height: u32, rgb: &[u8]) -> Image {
    image(stamp_ns, frame_id, width, height, "rgb8", 3, rgb.to_vec())
}

pub fn depth_32fc1(stamp_ns: i64, frame_id: &str, width: u32, height: u32, depth: &[f32]) -> Image {
    image(stamp_ns, frame_id, width, height, "32FC1", 4, depth.iter().flat_map(|z| z.to_le_bytes()).collect())
}

pub fn labels_32sc1(stamp_ns: i64, frame_id: &str, width: u32, height: u32, labels: &[i32]) -> Image {
    image(stamp_ns, frame_id, width, height, "32SC1", 4, labels.iter().flat_map(|l| l.to_le_bytes()).collect())
}

/// CDR of an rgb8 image: [`rgb8`]`(..).to_cdr()` with the pixels copied once, straight
/// from the frame into the message (the image is 2.8 MB at 1280x720, 10 times a second).
pub fn rgb8_cdr(stamp_ns: i64, frame_id: &str, width: u32, height: u32, rgb: &[u8]) -> Vec<u8> {
    image_cdr(image(stamp_ns, frame_id, width, height, "rgb8", 3, Vec::new()), rgb)
}

/// [`depth_32fc1`]`(..).to_cdr()` with one copy of the pixels.
pub fn depth_32fc1_cdr(stamp_ns: i64, frame_id: &str, width: u32, height: u32, depth: &[f32]) -> Vec<u8> {
    image_cdr(image(stamp_ns, frame_id, width, height, "32FC1", 4, Vec::new()), &le_words(depth, |v| v.to_le_bytes()))
}

/// [`labels_32sc1`]`(..).to_cdr()` with one copy of the pixels.
pub fn labels_32sc1_cdr(stamp_ns: i64, frame_id: &str, width: u32, height: u32, labels: &[i32]) -> Vec<u8> {
    image_cdr(image(stamp_ns, frame_id, width, height, "32SC1", 4, Vec::new()), &le_words(labels, |v| v.to_le_bytes()))
}

/// The CDR of `head` (an Image without data) with `data` as its data: the byte sequence is
/// the last field, so its length (the last 4 bytes, 0) is replaced and the bytes follow.
fn image_cdr(head: Image, data: &[u8]) -> Vec<u8> {
    let head = head.to_cdr();
    let mut out = Vec::with_capacity(head.len() + data.len());
    out.extend_from_slice(&head[..head.len() - 4]);
    out.extend_from_slice(&u32::try_from(data.len()).expect("image under 4 GB").to_le_bytes());
    out.extend_from_slice(data);
    out
}

/// 4-byte pixels as the little-endian words the encodings name: on a little-endian machine,
/// their memory as it is.
fn le_words<T: bytemuck::Pod>(px: &[T], le: impl Fn(&T) -> [u8; 4]) -> std::borrow::Cow<'_, [u8]> {
    if cfg!(target_endian = "little") {
        std::borrow::Cow::Borrowed(bytemuck::cast_slice(px))
    } else {
        std::borrow::Cow::Owned(px.iter().flat_map(le).collect())
    }
}

/// Pixels of a 32FC1 / 32SC1 image as 4-byte little-endian words (for tests and tools).
pub fn words(img: &Image) -> Result<Vec<[u8; 4]>, String> {
    if img.is_bigendian != 0 || img.step != 4 * img.width || img.data.len() != (img.step * img.height) as usize {
        return Err(format!(
            "{} image {}x{} step {} with {} bytes",
            img.encoding,
            img.width,
            img.height,
            img.step,
            img.data.len()
        ));
    }
    Ok(img.data.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect())
}

pub fn read_32fc1(img: &Image) -> Result<Vec<f32>, String> {
    if img.encoding != "32FC1" {
        return Err(format!("encoding {}", img.encoding));
    }
    Ok(words(img)?.into_iter().map(f32::from_le_bytes).collect())
}

pub fn read_32sc1(img: &Image) -> Result<Vec<i32>, String> {
    if img.encoding != "32SC1" {
        return Err(format!("encoding {}", img.encoding));
    }
    Ok(words(img)?.into_iter().map(i32::from_le_bytes).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direct_encodings_equal_the_messages() {
        let rgb: Vec<u8> = (0..5 * 3 * 3).map(|i| (i * 7) as u8).collect();
        let depth: Vec<f32> = (0..15).map(|i| i as f32 * 0.37 - 1.0).collect();
        let labels: Vec<i32> = (0..15).map(|i| i * 1000 - 7).collect();
        for frame_id in ["", "camera_optical_frame", "a"] {
            assert_eq!(rgb8_cdr(12_345, frame_id, 5, 3, &rgb), rgb8(12_345, frame_id, 5, 3, &rgb).to_cdr());
            assert_eq!(depth_32fc1_cdr(-7, frame_id, 5, 3, &depth), depth_32fc1(-7, frame_id, 5, 3, &depth).to_cdr());
            assert_eq!(labels_32sc1_cdr(0, frame_id, 5, 3, &labels), labels_32sc1(0, frame_id, 5, 3, &labels).to_cdr());
        }
        assert_eq!(rgb8_cdr(1, "x", 0, 0, &[]), rgb8(1, "x", 0, 0, &[]).to_cdr());
    }
}
