//! sensor_msgs/PointCloud2 in and out: the x, y, z fields by name and offset (float32 or
//! float64, either byte order), so clouds from any LiDAR driver layout decode.

use agrisim_error::err;
use agrisim_error::Result;
use agrisim_msgs::sensor_msgs::{PointCloud2, PointField};
use agrisim_msgs::std_msgs::Header;

/// The x, y, z of every finite point, in the cloud's frame.
pub fn decode_xyz(cloud: &PointCloud2) -> Result<Vec<[f32; 3]>> {
    let field = |name: &str| -> Result<(usize, u8)> {
        let f =
            cloud.fields.iter().find(|f| f.name == name).ok_or_else(|| err!("PointCloud2 has no field '{name}'"))?;
        match f.datatype {
            PointField::FLOAT32 | PointField::FLOAT64 => Ok((f.offset as usize, f.datatype)),
            d => Err(err!("PointCloud2 field '{name}' has datatype {d}, expected float32 or float64")),
        }
    };
    let fx = field("x")?;
    let fy = field("y")?;
    let fz = field("z")?;
    let step = cloud.point_step as usize;
    let (width, rows) = (cloud.width as usize, cloud.height.max(1) as usize);
    let need = |f: (usize, u8)| f.0 + if f.1 == PointField::FLOAT32 { 4 } else { 8 };
    if step == 0 || need(fx).max(need(fy)).max(need(fz)) > step {
        return Err(err!("PointCloud2 point_step {step} does not hold its x, y, z fields"));
    }
    // Sizes from the header are untrusted: every product is checked, so a crafted header is
    // an error, never an overflow or an out-of-bounds read.
    let too_big = || {
        err!(
            "PointCloud2 of {width} x {rows} points of {step} bytes (row_step {}) does not fit in {} bytes of data",
            cloud.row_step,
            cloud.data.len()
        )
    };
    let row_bytes = width.checked_mul(step).ok_or_else(too_big)?;
    let row_step = (cloud.row_step as usize).max(row_bytes);
    let n = width.checked_mul(rows).ok_or_else(too_big)?;
    let end = (rows - 1).checked_mul(row_step).and_then(|b| b.checked_add(row_bytes)).ok_or_else(too_big)?;
    if cloud.data.len() < end {
        return Err(too_big());
    }
    let big = cloud.is_bigendian;
    let read = |p: &[u8], (off, dt): (usize, u8)| -> f32 {
        if dt == PointField::FLOAT32 {
            let b: [u8; 4] = p[off..off + 4].try_into().unwrap();
            if big {
                f32::from_be_bytes(b)
            } else {
                f32::from_le_bytes(b)
            }
        } else {
            let b: [u8; 8] = p[off..off + 8].try_into().unwrap();
            (if big { f64::from_be_bytes(b) } else { f64::from_le_bytes(b) }) as f32
        }
    };
    let mut out = Vec::with_capacity(n);
    for r in 0..rows {
        for i in 0..cloud.width as usize {
            let p = &cloud.data[r * row_step + i * step..r * row_step + (i + 1) * step];
            let q = [read(p, fx), read(p, fy), read(p, fz)];
            // No-return points come as (0, 0, 0) (as the Livox driver sends them): skip them,
            // with anything non-finite, instead of reading them as obstacles at the sensor.
            if q.iter().all(|v| v.is_finite()) && q != [0.0; 3] {
                out.push(q);
            }
        }
    }
    Ok(out)
}

/// An unorganized little-endian cloud with float32 x, y, z, intensity (16 bytes a point).
pub fn encode_xyzi(header: Header, points: &[[f32; 4]]) -> PointCloud2 {
    let fields = ["x", "y", "z", "intensity"]
        .iter()
        .enumerate()
        .map(|(i, n)| PointField { name: n.to_string(), offset: 4 * i as u32, datatype: PointField::FLOAT32, count: 1 })
        .collect();
    let mut data = Vec::with_capacity(points.len() * 16);
    for p in points {
        for v in p {
            data.extend_from_slice(&v.to_le_bytes());
        }
    }
    PointCloud2 {
        header,
        height: 1,
        width: points.len() as u32,
        fields,
        is_bigendian: false,
        point_step: 16,
        row_step: 16 * points.len() as u32,
        data,
        is_dense: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let pts = [[1.0, 2.0, 3.0, 0.5], [-1.0, 0.0, 0.25, 1.0], [f32::NAN, 0.0, 0.0, 0.0]];
        let c = encode_xyzi(Header::default(), &pts);
        let d = decode_xyz(&c).unwrap();
        assert_eq!(d, vec![[1.0, 2.0, 3.0], [-1.0, 0.0, 0.25]]);
        let mut bad = c.clone();
        bad.fields.retain(|f| f.name != "z");
        assert!(decode_xyz(&bad).is_err());
        bad = c;
        bad.data.truncate(20);
        assert!(decode_xyz(&bad).is_err());
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(20_000))]
        /// Crafted headers (sizes up to u32::MAX, fields anywhere) over a little data: an
        /// error or points, never a panic or an overflow.
        #[test]
        fn crafted_clouds_never_panic(width in proptest::prelude::any::<u32>(), height in proptest::prelude::any::<u32>(), point_step in 0u32..64, row_step in proptest::prelude::any::<u32>(),
                                      offsets in proptest::collection::vec(0u32..80, 3), datatypes in proptest::collection::vec(6u8..9, 3), len in 0usize..512, small in proptest::prelude::any::<bool>()) {
            let fields = ["x", "y", "z"].iter().zip(offsets.iter().zip(&datatypes)).map(|(n, (&offset, &datatype))| PointField { name: n.to_string(), offset, datatype, count: 1 }).collect();
            let (width, height) = if small { (width % 9, height % 5) } else { (width, height) };
            let c = PointCloud2 { header: Header::default(), height, width, fields, is_bigendian: len % 2 == 0, point_step, row_step, data: vec![0x3f; len], is_dense: false };
            if let Ok(points) = decode_xyz(&c) {
                proptest::prop_assert!(points.len() <= len);
            }
        }
    }
}
