//! Frames as sensor_msgs/Image: rgb8, 32FC1 (depth, m) and 32SC1 (labels), little-endian.

use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::sensor_msgs::Image;
use agrisim_msgs::std_msgs::Header;

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
    image(
        stamp_ns,
        frame_id,
        width,
        height,
        "32FC1",
        4,
        depth.iter().flat_map(|z| z.to_le_bytes()).collect(),
    )
}

pub fn labels_32sc1(
    stamp_ns: i64,
    frame_id: &str,
    width: u32,
    height: u32,
    labels: &[i32],
) -> Image {
    image(
        stamp_ns,
        frame_id,
        width,
        height,
        "32SC1",
        4,
        labels.iter().flat_map(|l| l.to_le_bytes()).collect(),
    )
}

/// Pixels of a 32FC1 / 32SC1 image as 4-byte little-endian words (for tests and tools).
pub fn words(img: &Image) -> Result<Vec<[u8; 4]>, String> {
    if img.is_bigendian != 0
        || img.step != 4 * img.width
        || img.data.len() != (img.step * img.height) as usize
    {
        return Err(format!(
            "{} image {}x{} step {} with {} bytes",
            img.encoding,
            img.width,
            img.height,
            img.step,
            img.data.len()
        ));
    }
    Ok(img
        .data
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect())
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
