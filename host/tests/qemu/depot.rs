//! Generated maps the end-to-end tests share: a 604 x 307 depot, the shape of Nav2's sample
//! depot (`large.rs` and `soak_twin.rs` use it).

use ohaca_host::rng::Rng;
use ohaca_host::Map;

/// A 604 x 307 depot: outer walls, racks (blocks 2 cells deep, 20-40 long) in rows with aisles,
/// a few pillars and 1 % noise; the lower-left and upper-right corners are free.
pub fn depot(seed: u64) -> Map {
    let mut rng = Rng(seed);
    let (w, h) = (604u16, 307u16);
    let mut blocked = vec![false; usize::from(w) * usize::from(h)];
    let set = |x: u16, y: u16, b: &mut Vec<bool>| {
        if x < w && y < h {
            b[usize::from(y) * usize::from(w) + usize::from(x)] = true;
        }
    };
    for x in 0..w {
        set(x, 0, &mut blocked);
        set(x, h - 1, &mut blocked);
    }
    for y in 0..h {
        set(0, y, &mut blocked);
        set(w - 1, y, &mut blocked);
    }
    let mut y = 20;
    while y + 2 < h - 20 {
        let mut x = 30 + rng.below(10) as u16;
        while x < w - 40 {
            let len = 20 + rng.below(21) as u16;
            for dx in 0..len.min(w - 30 - x) {
                set(x + dx, y, &mut blocked);
                set(x + dx, y + 1, &mut blocked);
            }
            x += len + 6 + rng.below(6) as u16;
        }
        y += 9 + rng.below(4) as u16;
    }
    for _ in 0..60 {
        let (px, py) = (
            rng.below(usize::from(w)) as u16,
            rng.below(usize::from(h)) as u16,
        );
        for d in 0..9 {
            set(px + d % 3, py + d / 3, &mut blocked);
        }
    }
    for c in blocked.iter_mut() {
        if rng.chance(0.01) {
            *c = true;
        }
    }
    for (x, y) in [(1, h - 2), (w - 2, 1), (2, h - 2), (1, h - 3)] {
        blocked[usize::from(y) * usize::from(w) + usize::from(x)] = false;
    }
    Map::from_fn(w, h, |x, y| {
        blocked[usize::from(y) * usize::from(w) + usize::from(x)]
    })
}
