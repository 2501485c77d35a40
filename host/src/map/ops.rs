//! Operations on a loaded map, to prepare it for a robot and a device: obstacle inflation and
//! resampling to coarser cells ([`super::prepare`] does both as the map flags ask); fitting a
//! device's capacity (crop, then resample) is [`super::fit`].
//!
//! - [`inflate`] blocks every cell whose centre lies within a radius of a blocked cell's centre,
//!   so a robot of that radius, planned as a point, keeps clear of obstacles. The map's border is
//!   not an obstacle.
//! - [`resample`] makes cells `factor` times larger (in each direction): a coarse cell is blocked
//!   if any fine cell it overlaps is blocked. With a metric frame the coarse grid is anchored at
//!   the map's lower-left corner (the ROS origin), so the origin stays valid; without one, at the
//!   top-left corner (cell `(0, 0)`). A coarse cell on the far edge that only partly covers the
//!   map looks at the fine cells it does cover.
//!
//! Fitting a map to a device (crop, then resample) is [`super::fit`].

use ohaca::Point;

use super::bitmap::Map;
use super::metric::MapFrame;

/// Block every cell whose centre is within `radius` cells (Euclidean, centre to centre) of a
/// blocked cell's centre. `radius <= 0` (or not finite) leaves the map as it is.
///
/// The exact squared distance of every cell to its nearest obstacle comes from a linear-time
/// distance transform ([`squared_distances`]), so the cost does not grow with the radius: a
/// radius larger than the map is as cheap as a small one.
pub fn inflate(map: &Map, radius: f64) -> Map {
    if !(radius.is_finite() && radius > 0.0) {
        return map.clone();
    }
    // The epsilon keeps cells exactly on the circle inside.
    let r2 = radius * radius + 1e-9;
    let d2 = squared_distances(map);
    Map::from_fn(map.width, map.height, |x, y| {
        d2.get(usize::from(y) * usize::from(map.width) + usize::from(x))
            .is_none_or(|&d| d <= r2)
    })
}

/// Stands for "no obstacle in reach": larger than any squared distance on a map (at most
/// 2 x 65535^2), small enough that sums with squares of coordinates stay finite.
const FAR: f64 = 1e20;

/// Squared Euclidean distance, in cells, from each cell's centre to the nearest blocked cell's
/// centre (0 on obstacles, at least [`FAR`] when the map has none), row-major.
///
/// The separable transform of Felzenszwalb and Huttenlocher ("Distance transforms of sampled
/// functions", 2012): a 1-D transform down every column, then along every row, `O(width x
/// height)` in all. Every finite value is an exact integer.
pub fn squared_distances(map: &Map) -> Vec<f64> {
    let (w, h) = (usize::from(map.width), usize::from(map.height));
    let mut d: Vec<f64> = (0..map.height)
        .flat_map(|y| (0..map.width).map(move |x| (x, y)))
        .map(|(x, y)| {
            if map.is_blocked(Point::new(x, y)) {
                0.0
            } else {
                FAR
            }
        })
        .collect();
    let n = w.max(h);
    let mut line = vec![0.0; n];
    let mut scratch = Envelope::new(n);
    // Columns: element `i` of column `x` is cell `i * w + x`; rows: cell `y * w + i`.
    for x in 0..w {
        transform_line(&mut d, h, |i| i * w + x, &mut line, &mut scratch);
    }
    for y in 0..h {
        transform_line(&mut d, w, |i| y * w + i, &mut line, &mut scratch);
    }
    d
}

/// Scratch space of the 1-D transform: the parabolas of the lower envelope (`v`) and the
/// boundaries between them (`z`).
struct Envelope {
    v: Vec<usize>,
    z: Vec<f64>,
}

impl Envelope {
    fn new(n: usize) -> Envelope {
        Envelope {
            v: vec![0; n.max(1)],
            z: vec![0.0; n + 1],
        }
    }
}

/// The 1-D squared distance transform of the `len` values of `d` at `index(0..len)`, in place:
/// `d[q] = min over p of (d[p] + (q - p)^2)`.
fn transform_line(
    d: &mut [f64],
    len: usize,
    index: impl Fn(usize) -> usize,
    line: &mut [f64],
    e: &mut Envelope,
) {
    if len == 0 {
        return;
    }
    for (i, slot) in line.iter_mut().take(len).enumerate() {
        *slot = d.get(index(i)).copied().unwrap_or(FAR);
    }
    let f = |i: usize| line.get(i).copied().unwrap_or(FAR);
    let sq = |i: usize| (i as f64) * (i as f64);
    let (v, z) = (&mut e.v, &mut e.z);
    let set_v = |v: &mut Vec<usize>, k: usize, p: usize| {
        if let Some(s) = v.get_mut(k) {
            *s = p;
        }
    };
    let set_z = |z: &mut Vec<f64>, k: usize, s: f64| {
        if let Some(t) = z.get_mut(k) {
            *t = s;
        }
    };
    let mut k = 0usize;
    set_v(v, 0, 0);
    set_z(z, 0, f64::NEG_INFINITY);
    set_z(z, 1, f64::INFINITY);
    for q in 1..len {
        let mut s;
        loop {
            let p = v.get(k).copied().unwrap_or(0);
            // Where the parabola rooted at q overtakes the one rooted at p (p < q).
            s = ((f(q) + sq(q)) - (f(p) + sq(p))) / (2.0 * (q as f64 - p as f64));
            if k > 0 && s <= z.get(k).copied().unwrap_or(f64::NEG_INFINITY) {
                k -= 1;
            } else {
                break;
            }
        }
        k += 1;
        set_v(v, k, q);
        set_z(z, k, s);
        set_z(z, k + 1, f64::INFINITY);
    }
    let mut k = 0usize;
    for q in 0..len {
        while z.get(k + 1).is_some_and(|&b| b < q as f64) {
            k += 1;
        }
        let p = v.get(k).copied().unwrap_or(0);
        let dq = q as f64 - p as f64;
        if let Some(slot) = d.get_mut(index(q)) {
            *slot = dq * dq + f(p);
        }
    }
}

/// Why a map cannot be resampled.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ResampleError {
    /// The factor is below 1 or not finite.
    #[error("the new cell size must be at least the map's cell size (factor {0}, expected >= 1)")]
    Factor(f64),
}

/// Cells `factor` times larger (`factor >= 1`, need not be whole). `bottom_anchor` anchors the
/// coarse grid at the lower-left corner (maps with a metric frame), else at the top-left. A
/// coarse cell is blocked if any fine cell it overlaps (with positive area) is blocked.
pub fn resample(map: &Map, factor: f64, bottom_anchor: bool) -> Result<Map, ResampleError> {
    if !(factor.is_finite() && factor >= 1.0) {
        return Err(ResampleError::Factor(factor));
    }
    // Tolerance for factors like 0.15 / 0.05 = 2.9999999999999996.
    const EPS: f64 = 1e-9;
    let coarse = |n: u16| -> u16 {
        let c = (f64::from(n) / factor - EPS).ceil().max(1.0);
        c.min(f64::from(n)) as u16
    };
    let (cw, ch) = (coarse(map.width), coarse(map.height));
    // Fine cells [lo, hi] overlapped by coarse cell `c` along a side of `n` fine cells.
    let span = |c: u16, n: u16| -> (u16, u16) {
        let lo = (f64::from(c) * factor + EPS).floor();
        let hi = (f64::from(c + 1) * factor - EPS).ceil() - 1.0;
        let last = f64::from(n) - 1.0;
        (lo.min(last) as u16, hi.clamp(lo.min(last), last) as u16)
    };
    Ok(Map::from_fn(cw, ch, |cx, cy| {
        let (x0, x1) = span(cx, map.width);
        let (y0, y1) = if bottom_anchor {
            // Rows counted from the bottom in both grids.
            let (b0, b1) = span(ch - 1 - cy, map.height);
            (map.height - 1 - b1, map.height - 1 - b0)
        } else {
            span(cy, map.height)
        };
        (y0..=y1).any(|y| (x0..=x1).any(|x| map.is_blocked(Point::new(x, y))))
    }))
}

/// The frame of a map resampled by `factor` with [`resample`] (bottom anchor): the same origin
/// and yaw, `factor` times the resolution, the coarse sides.
pub fn resample_frame(frame: &MapFrame, coarse: &Map, factor: f64) -> MapFrame {
    MapFrame {
        resolution: frame.resolution * factor,
        width: coarse.width,
        height: coarse.height,
        ..*frame
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::Format;

    fn text(s: &str) -> Map {
        Map::parse(s, "t", Format::Text).unwrap()
    }

    #[test]
    fn inflate_radius_one_is_the_plus() {
        let m = text(".....\n.....\n..#..\n.....\n.....\n");
        assert_eq!(
            inflate(&m, 1.0).to_text(),
            ".....\n..#..\n.###.\n..#..\n.....\n"
        );
        assert_eq!(
            inflate(&m, 1.5).to_text(),
            ".....\n.###.\n.###.\n.###.\n.....\n",
            "sqrt 2 <= 1.5"
        );
        assert_eq!(
            inflate(&m, 2.0).to_text(),
            "..#..\n.###.\n#####\n.###.\n..#..\n"
        );
        assert_eq!(inflate(&m, 0.0), m);
        assert_eq!(inflate(&m, 0.99), m);
    }

    #[test]
    fn inflate_matches_brute_force() {
        let m = Map::from_fn(23, 17, |x, y| {
            (x * 7 + y * 11) % 13 == 0 || (x > 15 && y > 10)
        });
        for r in [0.5, 1.0, 1.42, 2.3, 3.0, 4.7] {
            let fast = inflate(&m, r);
            let slow = Map::from_fn(m.width, m.height, |x, y| {
                (0..m.height).any(|by| {
                    (0..m.width).any(|bx| {
                        let d2 = (f64::from(x) - f64::from(bx)).powi(2)
                            + (f64::from(y) - f64::from(by)).powi(2);
                        m.is_blocked(Point::new(bx, by)) && d2 <= r * r + 1e-9
                    })
                })
            });
            assert_eq!(fast, slow, "radius {r}");
        }
    }

    #[test]
    fn distances_are_exact() {
        let m = Map::from_fn(31, 9, |x, y| {
            (x * 5 + y * 3) % 17 == 0 || (x == 30 && y == 8)
        });
        let d = squared_distances(&m);
        for y in 0..m.height {
            for x in 0..m.width {
                let want = (0..m.height)
                    .flat_map(|by| (0..m.width).map(move |bx| (bx, by)))
                    .filter(|&(bx, by)| m.is_blocked(Point::new(bx, by)))
                    .map(|(bx, by)| {
                        (f64::from(x) - f64::from(bx)).powi(2)
                            + (f64::from(y) - f64::from(by)).powi(2)
                    })
                    .fold(f64::INFINITY, f64::min);
                let got = d[usize::from(y) * 31 + usize::from(x)];
                assert_eq!(got, want, "{x},{y}");
            }
        }
        // No obstacle: everything is far, nothing is inflated.
        let free = Map::from_fn(7, 3, |_, _| false);
        assert!(squared_distances(&free).iter().all(|&v| v >= FAR));
        assert_eq!(inflate(&free, 1e6), free);
        // One row, one column.
        let row = text("..#....\n");
        assert_eq!(
            squared_distances(&row),
            vec![4.0, 1.0, 0.0, 1.0, 4.0, 9.0, 16.0]
        );
        assert_eq!(inflate(&row, 2.0).to_text(), "#####..\n");
    }

    #[test]
    fn a_huge_radius_is_cheap_and_blocks_everything() {
        // The old disc-of-offsets inflation allocated (2r + 1)^2 offsets: at r = 1e9 cells that
        // was the whole memory. Now the cost does not depend on the radius.
        let m = Map::from_fn(300, 200, |x, y| x == 150 && y == 100);
        for r in [1e3, 1e9, f64::MAX] {
            let t = std::time::Instant::now();
            let i = inflate(&m, r);
            assert!(i.to_text().chars().all(|c| c == '#' || c == '\n'), "r {r}");
            assert!(t.elapsed().as_secs() < 20, "r {r}: {:?}", t.elapsed());
        }
    }

    #[test]
    fn resample_any_blocked_pixel_blocks() {
        let m = text("......\n......\n....#.\n......\n");
        // Top-left anchor, factor 2: 3x2 coarse cells.
        assert_eq!(resample(&m, 2.0, false).unwrap().to_text(), "...\n..#\n");
        // Bottom-left anchor: same here (height 4 is even).
        assert_eq!(resample(&m, 2.0, true).unwrap().to_text(), "...\n..#\n");
        // Factor 1 is the identity.
        assert_eq!(resample(&m, 1.0, true).unwrap(), m);
        assert!(resample(&m, 0.5, true).is_err());
        assert!(resample(&m, f64::NAN, true).is_err());
    }

    #[test]
    fn resample_anchor_matters_for_partial_cells() {
        // 3 rows, factor 2: two coarse rows; the partial one is at the top (bottom anchor) or
        // at the bottom (top anchor).
        let m = text("#..\n...\n...\n");
        let b = resample(&m, 2.0, true).unwrap();
        assert_eq!(
            b.to_text(),
            "#.\n..\n",
            "top coarse row covers fine row 0 only"
        );
        let t = resample(&m, 2.0, false).unwrap();
        assert_eq!(t.to_text(), "#.\n..\n");
        let m = text("...\n...\n#..\n");
        assert_eq!(resample(&m, 2.0, true).unwrap().to_text(), "..\n#.\n");
        assert_eq!(resample(&m, 2.0, false).unwrap().to_text(), "..\n#.\n");
        let m = text("...\n#..\n...\n");
        // Bottom anchor: fine row 1 is in the bottom coarse row (fine rows 1-2).
        assert_eq!(resample(&m, 2.0, true).unwrap().to_text(), "..\n#.\n");
        // Top anchor: fine row 1 is in the top coarse row (fine rows 0-1).
        assert_eq!(resample(&m, 2.0, false).unwrap().to_text(), "#.\n..\n");
    }

    #[test]
    fn fractional_factor_overlaps() {
        // Factor 1.5 on 3 columns: coarse 0 covers [0, 1.5) = fine 0-1, coarse 1 covers
        // [1.5, 3) = fine 1-2; fine column 1 touches both.
        let m = text(".#.\n");
        assert_eq!(resample(&m, 1.5, false).unwrap().to_text(), "##\n");
        let m = text("#..\n");
        assert_eq!(resample(&m, 1.5, false).unwrap().to_text(), "#.\n");
        // 0.15 / 0.05 is not exactly 3 in floating point.
        let m = text("..#...\n");
        assert_eq!(resample(&m, 0.15 / 0.05, false).unwrap().to_text(), "#.\n");
    }

    #[test]
    fn resampled_frame_keeps_the_origin() {
        let f = MapFrame {
            resolution: 0.05,
            origin: [1.0, -2.0],
            yaw: 0.0,
            width: 6,
            height: 3,
        };
        let m = Map::from_fn(6, 3, |_, _| false);
        let c = resample(&m, 2.0, true).unwrap();
        let g = resample_frame(&f, &c, 2.0);
        assert_eq!((g.width, g.height, g.resolution), (3, 2, 0.1));
        // The coarse lower-left cell's centre is at origin + half a coarse cell.
        let p = g.to_metres(Point::new(0, 1));
        assert!(
            (p[0] - 1.05).abs() < 1e-12 && (p[1] + 1.95).abs() < 1e-12,
            "{p:?}"
        );
        // A fine cell and the coarse cell containing it agree in metres.
        for (x, y) in [(0u16, 2u16), (5, 0), (3, 1)] {
            let m = f.to_metres(Point::new(x, y));
            let c = g.cell(m).unwrap();
            assert_eq!(c, Point::new(x / 2, if y == 0 { 0 } else { 1 }), "{x},{y}");
        }
    }
}
