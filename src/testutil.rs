//! Test support shared by the unit tests (compiled for tests only).

/// A map from text rows (`#` blocked, anything else free) as `(bits, width, height)`.
pub fn bits(rows: &[&str]) -> (Vec<u8>, u16, u16) {
    let w = rows[0].len();
    let mut b = vec![0u8; (w * rows.len()).div_ceil(8)];
    for (y, r) in rows.iter().enumerate() {
        for (x, c) in r.chars().enumerate() {
            if c == '#' {
                let i = y * w + x;
                b[i / 8] |= 1 << (i % 8);
            }
        }
    }
    (b, w as u16, rows.len() as u16)
}
