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

/// A random map of `w x h` cells, each blocked with probability `density`, as bits.
pub fn random_bits(rng: &mut crate::rng::Xoshiro128pp, w: u16, h: u16, density: f32) -> Vec<u8> {
    let cells = usize::from(w) * usize::from(h);
    let mut b = vec![0u8; cells.div_ceil(8)];
    for i in 0..cells {
        if rng.next_unit() < density {
            b[i / 8] |= 1 << (i % 8);
        }
    }
    b
}

/// A random map (`density` blocked) and a valid path on it from its left edge that heads right
/// (E, SE or NE three times in five, otherwise any allowed step, never into a cell it visited)
/// for about `steps` steps or to the right edge: a colony-like wander. At least `min` cells.
pub fn heading_walk(
    rng: &mut crate::rng::Xoshiro128pp,
    w: u16,
    h: u16,
    density: f32,
    steps: usize,
    min: usize,
) -> (Vec<u8>, Vec<crate::map::grid::Point>) {
    use crate::map::grid::{Grid, Point};
    loop {
        let b = random_bits(rng, w, h, density);
        let g = Grid::new(w, h, &b).unwrap();
        let start = Point::new(0, (rng.next_word() % u32::from(h)) as u16);
        if !g.is_free(start) {
            continue;
        }
        let mut path = vec![start];
        let mut seen = vec![false; usize::from(w) * usize::from(h)];
        seen[usize::from(start.y) * usize::from(w)] = true;
        let mut tries = 0;
        while path.len() <= steps && tries < 20 * steps {
            tries += 1;
            let p = *path.last().unwrap();
            if p.x + 1 >= w {
                break;
            }
            // NE, E, SE are 7, 0, 1 in the crate's order.
            let d = if rng.next_unit() < 0.6 {
                [7u8, 0, 1][(rng.next_word() % 3) as usize]
            } else {
                (rng.next_word() % 8) as u8
            };
            if let Some(q) = g.step(p, d) {
                let i = usize::from(q.y) * usize::from(w) + usize::from(q.x);
                if !seen[i] {
                    seen[i] = true;
                    path.push(q);
                }
            }
        }
        if path.len() >= min {
            return (b, path);
        }
    }
}
