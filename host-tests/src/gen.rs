//! Random maps and start/goal pairs for proptest.
//!
//! Two map families, so that both scattered obstacles and long walls with dead ends and pockets
//! get exercised:
//!
//! - [`noise_map`]: every cell blocked independently with a random density;
//! - [`walls_map`]: random horizontal and vertical wall segments plus a little noise.
//!
//! [`case`] picks one of them and a start and goal cell, which it clears (so the endpoints are
//! valid; the error paths for bad endpoints are tested separately). Everything shrinks towards
//! small, empty maps.
//!
//! [`maze`] and [`far_pair`] make fresh wide-corridor mazes (Moving AI's `maze-*-*-W` style, any
//! corridor width) and a far start/goal pair in them, deterministically from a seed: the
//! `mazes` example and `tests/it/mazes.rs` plan on them.

use ohaca::Point;
use proptest::collection::vec;
use proptest::prelude::*;

use crate::maps::Map;

/// Maps of `1..=max_w` x `1..=max_h` cells, each blocked with a probability drawn from
/// `0..max_density`.
pub fn noise_map(max_w: u16, max_h: u16, max_density: f64) -> impl Strategy<Value = Map> {
    (1..=max_w, 1..=max_h, 0.0..max_density).prop_flat_map(|(w, h, d)| {
        vec(prop::bool::weighted(d), usize::from(w) * usize::from(h))
            .prop_map(move |cells| Map::new(w, h, cells))
    })
}

/// Maps of `2..=max_w` x `2..=max_h` cells with up to 8 straight walls and light noise.
pub fn walls_map(max_w: u16, max_h: u16) -> impl Strategy<Value = Map> {
    (2..=max_w, 2..=max_h).prop_flat_map(|(w, h)| {
        let wall = (0..w, 0..h, 1..=w.max(h), any::<bool>());
        (
            vec(wall, 0..8),
            vec(prop::bool::weighted(0.08), usize::from(w) * usize::from(h)),
        )
            .prop_map(move |(walls, noise)| {
                let mut m = Map::new(w, h, noise);
                for (x, y, len, horizontal) in walls {
                    for k in 0..len {
                        let (cx, cy) = if horizontal { (x + k, y) } else { (x, y + k) };
                        if cx < w && cy < h {
                            m.set(Point::new(cx, cy), true);
                        }
                    }
                }
                m
            })
    })
}

/// Either map family, up to `max_side` x `max_side`.
pub fn any_map(max_side: u16) -> impl Strategy<Value = Map> {
    prop_oneof![
        3 => noise_map(max_side, max_side, 0.5),
        2 => walls_map(max_side, max_side),
    ]
}

/// A map with a start and a goal cell, both made free.
pub fn case(max_side: u16) -> impl Strategy<Value = (Map, Point, Point)> {
    any_map(max_side).prop_flat_map(|m| {
        let n = m.cells();
        (Just(m), 0..n, 0..n).prop_map(|(mut m, s, g)| {
            let (s, g) = (m.point(s), m.point(g));
            m.set(s, false);
            m.set(g, false);
            (m, s, g)
        })
    })
}

/// A map with arbitrary start and goal points, possibly blocked and possibly up to 2 cells
/// beyond the border (for the error paths).
pub fn raw_case(max_side: u16) -> impl Strategy<Value = (Map, Point, Point)> {
    any_map(max_side).prop_flat_map(|m| {
        let (w, h) = (m.width() + 2, m.height() + 2);
        (Just(m), 0..w, 0..h, 0..w, 0..h)
            .prop_map(|(m, sx, sy, gx, gy)| (m, Point::new(sx, sy), Point::new(gx, gy)))
    })
}

/// The proptest configuration the tests use: `cases` cases, and failing inputs saved next to the
/// test file (`tests/NAME.regressions`), since integration tests have no `lib.rs` beside them for
/// proptest's default location.
pub fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        failure_persistence: Some(Box::new(
            proptest::test_runner::FileFailurePersistence::WithSource("regressions"),
        )),
        ..ProptestConfig::default()
    }
}

/// SplitMix64: the generator of [`maze`] and of the `fresh` example's maps (deterministic from its
/// seed, independent of proptest and of the planner's own generator).
pub struct Mix(pub u64);

impl Mix {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A number below `n` (`n > 0`).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }
}

/// A perfect maze in the style of Moving AI's `maze-*-*-W` maps: corridors `width` cells wide
/// between walls one cell thick, on a `side x side` map (rooms `(side - 1) / (width + 1)` a side;
/// cells beyond the last room stay blocked). The passages are a randomised depth-first spanning
/// tree of the rooms, so between any two cells there is exactly one corridor route, and the
/// number of dead-end pockets is that of a classic "recursive backtracker" maze. Deterministic in
/// `seed`.
pub fn maze(side: u16, width: u16, seed: u64) -> Map {
    let w = usize::from(width.max(1));
    let s = usize::from(side);
    let rooms = s.saturating_sub(1) / (w + 1);
    let mut blocked = vec![true; s * s];
    let mut open = |x0: usize, y0: usize, x1: usize, y1: usize| {
        for y in y0..y1 {
            for x in x0..x1 {
                blocked[y * s + x] = false;
            }
        }
    };
    // Room (i, j) covers cells 1 + i (w + 1) .. + w in x, likewise in y.
    let origin = |i: usize| 1 + i * (w + 1);
    for j in 0..rooms {
        for i in 0..rooms {
            open(origin(i), origin(j), origin(i) + w, origin(j) + w);
        }
    }
    let mut rng = Mix(seed ^ (u64::from(side) << 32) ^ u64::from(width));
    let mut seen = vec![false; rooms * rooms];
    let mut stack = Vec::new();
    if rooms > 0 {
        seen[0] = true;
        stack.push(0usize);
    }
    while let Some(&r) = stack.last() {
        let (i, j) = (r % rooms, r / rooms);
        let mut next = [(0usize, 0usize); 4];
        let mut n = 0;
        for (di, dj) in [(1i64, 0i64), (-1, 0), (0, 1), (0, -1)] {
            let (ni, nj) = (i as i64 + di, j as i64 + dj);
            if ni >= 0 && nj >= 0 && (ni as usize) < rooms && (nj as usize) < rooms {
                let k = nj as usize * rooms + ni as usize;
                if !seen[k] {
                    next[n] = (ni as usize, nj as usize);
                    n += 1;
                }
            }
        }
        if n == 0 {
            stack.pop();
            continue;
        }
        let (ni, nj) = next[rng.below(n as u64) as usize];
        // Knock down the one-cell wall between the two rooms, across the corridor's width.
        if ni != i {
            let x = origin(i.min(ni)) + w;
            open(x, origin(j), x + 1, origin(j) + w);
        } else {
            let y = origin(j.min(nj)) + w;
            open(origin(i), y, origin(i) + w, y + 1);
        }
        let k = nj * rooms + ni;
        seen[k] = true;
        stack.push(k);
    }
    Map::new(side, side, blocked)
}

/// Start and goal in the two rooms farthest apart along the maze's corridors that `maze` can
/// make (a corner room and the room the depth-first tree puts farthest from it): picked by two
/// breadth-first passes over the cells, so the pair is one of the longest the map has. `k`
/// varies the choice: the `k`-th farthest cell from a corner, then its farthest cell.
pub fn far_pair(map: &Map, k: usize) -> Option<(Point, Point)> {
    let far = |from: Point| -> Vec<(usize, Point)> {
        let (w, h) = (usize::from(map.width()), usize::from(map.height()));
        let mut dist = vec![usize::MAX; w * h];
        let mut queue = std::collections::VecDeque::new();
        dist[map.index(from)] = 0;
        queue.push_back(from);
        let mut order = Vec::new();
        while let Some(p) = queue.pop_front() {
            let d = dist[map.index(p)];
            order.push((d, p));
            for (dx, dy) in [(1i64, 0i64), (-1, 0), (0, 1), (0, -1)] {
                let (x, y) = (i64::from(p.x) + dx, i64::from(p.y) + dy);
                if map.free(x, y) {
                    let q = Point::new(x as u16, y as u16);
                    if dist[map.index(q)] == usize::MAX {
                        dist[map.index(q)] = d + 1;
                        queue.push_back(q);
                    }
                }
            }
        }
        order.sort_by_key(|e| std::cmp::Reverse(e.0));
        order
    };
    let corner = (0..map.cells())
        .map(|i| map.point(i))
        .find(|&p| map.is_free(p))?;
    let a = far(corner);
    // Skip ahead by whole rooms' worth of cells so that different `k` give different starts.
    let start = a.get((k * 97) % a.len().max(1))?.1;
    let b = far(start);
    Some((start, b.first()?.1))
}
