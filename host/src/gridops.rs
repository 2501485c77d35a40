//! Map preparation for real robots: obstacle inflation and resampling to coarser cells.
//!
//! - [`inflate`] blocks every cell whose centre lies within a radius of a blocked cell's centre,
//!   so a robot of that radius, planned as a point, keeps clear of obstacles. The map's border is
//!   not an obstacle.
//! - [`resample`] makes cells `factor` times larger (in each direction): a coarse cell is blocked
//!   if any fine cell it overlaps is blocked. With a metric frame the coarse grid is anchored at
//!   the map's lower-left corner (the ROS origin), so the origin stays valid; without one, at the
//!   top-left corner (cell `(0, 0)`). A coarse cell on the far edge that only partly covers the
//!   map looks at the fine cells it does cover.

use ohaca::Point;

use crate::frame::Frame;
use crate::map::Map;

/// Block every cell whose centre is within `radius` cells (Euclidean, centre to centre) of a
/// blocked cell's centre. `radius <= 0` (or not finite) leaves the map as it is.
pub fn inflate(map: &Map, radius: f64) -> Map {
    if !(radius.is_finite() && radius > 0.0) {
        return map.clone();
    }
    let (w, h) = (i64::from(map.width), i64::from(map.height));
    // A disc of offsets; the epsilon keeps cells exactly on the circle inside.
    let r2 = radius * radius + 1e-9;
    let reach = radius.floor().min(f64::from(u16::MAX)) as i64;
    let disc: Vec<(i64, i64)> = (-reach..=reach)
        .flat_map(|dy| (-reach..=reach).map(move |dx| (dx, dy)))
        .filter(|&(dx, dy)| ((dx * dx + dy * dy) as f64) <= r2)
        .collect();
    let blocked = |x: i64, y: i64| -> bool {
        match (u16::try_from(x), u16::try_from(y)) {
            (Ok(x), Ok(y)) => map.is_blocked(Point::new(x, y)),
            _ => true,
        }
    };
    let mut out = vec![false; map.cells()];
    for y in 0..h {
        for x in 0..w {
            if !blocked(x, y) {
                continue;
            }
            let i = (y * w + x) as usize;
            if let Some(c) = out.get_mut(i) {
                *c = true;
            }
            // Only obstacle cells with a free 4-neighbour inside the map can be the nearest
            // obstacle of a free cell, so the others need not spread.
            let edge = [(1, 0), (-1, 0), (0, 1), (0, -1)].iter().any(|&(dx, dy)| {
                let (nx, ny) = (x + dx, y + dy);
                nx >= 0 && ny >= 0 && nx < w && ny < h && !blocked(nx, ny)
            });
            if !edge {
                continue;
            }
            for &(dx, dy) in &disc {
                let (nx, ny) = (x + dx, y + dy);
                if nx >= 0 && ny >= 0 && nx < w && ny < h {
                    if let Some(c) = out.get_mut((ny * w + nx) as usize) {
                        *c = true;
                    }
                }
            }
        }
    }
    Map::from_fn(map.width, map.height, |x, y| {
        out.get(usize::from(y) * usize::from(map.width) + usize::from(x))
            .copied()
            .unwrap_or(true)
    })
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
pub fn resample_frame(frame: &Frame, coarse: &Map, factor: f64) -> Frame {
    Frame {
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
        let f = Frame {
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
