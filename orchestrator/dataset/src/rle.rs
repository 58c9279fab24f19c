//! COCO run-length encoding of a binary mask: runs over the pixels in column-major order
//! (down each column, then the next column), starting with a run of zeros (possibly empty),
//! and the compact string form of those runs that pycocotools reads (`counts` as a string).
//!
//! The string form: each run length, from the third on, is written as its difference to the
//! run two before it; every value is cut into 5-bit groups, least significant first, each
//! group a character `48 + group`, with bit 0x20 set while more groups follow. A group's bit
//! 0x10 carries the sign, so a value ends when the remaining bits are all sign bits.

#[cfg(test)]
/// Run lengths of `mask` (row-major, `width x height`, true = inside) in COCO order.
pub fn runs(mask: impl Fn(usize) -> bool, width: usize, height: usize) -> Vec<u64> {
    let mut out = Vec::new();
    let (mut current, mut length) = (false, 0u64);
    for u in 0..width {
        for v in 0..height {
            let m = mask(v * width + u);
            if m != current {
                out.push(length);
                current = m;
                length = 0;
            }
            length += 1;
        }
    }
    out.push(length);
    out
}

/// The compact string of `runs` (see the module docs).
pub fn to_string(runs: &[u64]) -> String {
    let mut s = String::new();
    for (i, &r) in runs.iter().enumerate() {
        let mut x = r as i64;
        if i > 2 {
            x -= runs[i - 2] as i64;
        }
        loop {
            let mut c = x & 0x1f;
            x >>= 5;
            let more = if c & 0x10 != 0 { x != -1 } else { x != 0 };
            if more {
                c |= 0x20;
            }
            s.push(char::from(48 + c as u8));
            if !more {
                break;
            }
        }
    }
    s
}

/// Inverse of [`to_string`] (for tests and readers of the per-frame files).
pub fn from_string(s: &str) -> Result<Vec<u64>, String> {
    let bytes = s.as_bytes();
    let mut out: Vec<u64> = Vec::new();
    let mut p = 0;
    while p < bytes.len() {
        let (mut x, mut k) = (0i64, 0);
        loop {
            let c = *bytes.get(p).ok_or("truncated RLE string")? as i64 - 48;
            if !(0..64).contains(&c) || k > 60 {
                return Err(format!("bad RLE character at {p}"));
            }
            x |= (c & 0x1f) << (5 * k);
            p += 1;
            k += 1;
            if c & 0x20 == 0 {
                if c & 0x10 != 0 {
                    x |= -1i64 << (5 * k);
                }
                break;
            }
        }
        if out.len() > 2 {
            x += out[out.len() - 2] as i64;
        }
        out.push(u64::try_from(x).map_err(|_| "negative run in RLE string".to_string())?);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_are_column_major_and_start_with_zeros() {
        // 3 wide, 2 high: row 0 = 1 0 1, row 1 = 1 1 0 -> columns (1,1), (0,1), (1,0).
        let m = [true, false, true, true, true, false];
        assert_eq!(runs(|i| m[i], 3, 2), vec![0, 2, 1, 2, 1]);
        assert_eq!(runs(|_| false, 4, 4), vec![16]);
    }

    #[test]
    fn string_form_round_trips_and_matches_known_values() {
        // Small values are one character each: 48 + value.
        assert_eq!(to_string(&[0, 2, 1]), "021");
        // 40 = 0b01000 | 1 << 5: two groups, the first flagged.
        assert_eq!(to_string(&[40]), "X1");
        // Fourth run 1 after the second, 3: the difference -2 is one group with the sign bit (48 + 30).
        assert_eq!(to_string(&[5, 3, 7, 1]), "537N");
        let mut state = 12345u64;
        for _ in 0..200 {
            let n = (state % 40) as usize + 1;
            let runs: Vec<u64> = (0..n)
                .map(|_| {
                    state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                    (state >> 33) % 5000
                })
                .collect();
            assert_eq!(from_string(&to_string(&runs)).unwrap(), runs);
        }
    }
}
