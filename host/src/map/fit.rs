//! Fitting a map to a device: what `ohaca send` (and anything else that plans on a device) sends
//! when the map is larger than the device holds ([`Capacity`]: cells and longest side).
//!
//! In this order, and only as far as needed:
//! 1. **the map as it is**, when it fits ([`fits`]): full resolution, same cells;
//! 2. **cropped** to the bounding box of its free cells, with a margin of one blocked cell where
//!    the map has room. Cells outside a map are blocked for the planner, so the crop loses no
//!    path and changes no distance: a 384 x 384 ROS image whose known area is 80 x 80 goes up
//!    as 82 x 82 cells at full resolution. (Unknown cells count as free or blocked as `--unknown`
//!    says; blocked, the ROS default, is what makes the crop bite.)
//! 3. **resampled** (the crop), by the smallest whole factor `k` whose coarse map fits: a coarse
//!    cell is blocked if any fine cell it covers is (or lies outside the map), so every coarse path
//!    is a fine path. The coarse grid may start anywhere within `k` cells of the crop's corner:
//!    the offsets are tried in order until the start and the goal (free at full resolution) fall
//!    in free coarse cells. If no offset keeps them free at the smallest factor, the fitting
//!    **refuses** ([`FitError::EndpointLost`]) with the device's capacity, the cell size that
//!    would fit, and what to change, instead of planning from or to an obstacle.
//!
//! A [`Fitted`] map knows where it lies in the original one ([`Fitted::cell`] original → fitted,
//! [`Fitted::original`] fitted → original, the centre of the coarse cell), so replies go back in
//! the original frame; with a metric frame the fitted map gets its own ([`Fitted::metric`]), and
//! metres are the same in both.

use ohaca::protocol::Capacity;
use ohaca::Point;

use super::{Map, MapFrame};

/// True if `map` fits `capacity`: no more cells than it holds, and no side longer than
/// `max_side` (any shape within those: 604 x 307 is one map).
pub fn fits(map: &Map, capacity: &Capacity) -> bool {
    fits_size(map.width, map.height, capacity)
}

fn fits_size(w: u16, h: u16, capacity: &Capacity) -> bool {
    u32::from(w) * u32::from(h) <= capacity.cells && w.max(h) <= capacity.max_side
}

/// A map fitted to a device: a window of the original map (crop), at `factor` original cells per
/// cell along each side (1: full resolution).
#[derive(Clone, Debug, PartialEq)]
pub struct Fitted {
    /// Original cells per fitted cell, along each side (1: cropped only).
    pub factor: u16,
    /// The original cell at the top-left corner of fitted cell `(0, 0)` (may lie left of or above
    /// the original map when the coarse grid was shifted: those cells are blocked).
    pub origin: (i32, i32),
    /// The fitted map.
    pub map: Map,
    /// The fitted map's metric frame (maps with a resolution): the same metres as the original.
    pub metric: Option<MapFrame>,
    /// The original map's sides, for [`Fitted::original`].
    pub original_size: (u16, u16),
}

/// Why a map cannot be fitted to a device.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FitError {
    /// The map has no free cell at all.
    #[error("the map has no free cell")]
    NoFreeCell,
    /// Even one cell per map would not fit (a device without cells).
    #[error("the device holds no map at all ({cells} cells)")]
    NoRoom {
        /// The device's cells.
        cells: u32,
    },
    /// Every coarse grid that fits puts the start or the goal on an obstacle.
    #[error(
        "{which} {x},{y} is free at full resolution, but the map ({width}x{height} cells after \
         cropping to its free area) must be resampled to fit the device ({cells} cells, sides up \
         to {max_side}), and at {factor}x{factor} cells per cell{size} every grid puts an \
         obstacle in the {which}'s cell; choose a {which} farther from obstacles, a smaller \
         --inflate, or a coarser grid yourself with --cell (then start and goal are checked on it)"
    )]
    EndpointLost {
        /// "start" or "goal".
        which: &'static str,
        /// Its cell in the original map.
        x: u16,
        /// Its cell in the original map.
        y: u16,
        /// The cropped map's sides.
        width: u16,
        /// The cropped map's sides.
        height: u16,
        /// The smallest factor that fits.
        factor: u16,
        /// That factor as a cell size, e.g. " (0.15 m)", or empty.
        size: String,
        /// The device's cells.
        cells: u32,
        /// The device's longest side.
        max_side: u16,
    },
}

/// The bounding box `(x0, y0, x1, y1)` (inclusive) of the free cells, if any.
pub fn free_bounds(map: &Map) -> Option<(u16, u16, u16, u16)> {
    let mut b: Option<(u16, u16, u16, u16)> = None;
    for y in 0..map.height {
        for x in 0..map.width {
            if !map.is_blocked(Point::new(x, y)) {
                b = Some(match b {
                    None => (x, y, x, y),
                    Some((x0, y0, x1, y1)) => (x0.min(x), y0.min(y), x1.max(x), y1.max(y)),
                });
            }
        }
    }
    b
}

/// Fit `map` to `capacity` (see the module docs) so that every point of `endpoints` (free cells
/// of `map`: start, goal, start, goal, ...) stays free. `Ok(None)`: the map fits as it is.
pub fn fit(
    map: &Map,
    metric: Option<MapFrame>,
    capacity: &Capacity,
    endpoints: &[Point],
) -> Result<Option<Fitted>, FitError> {
    if fits(map, capacity) {
        return Ok(None);
    }
    if capacity.cells == 0 || capacity.max_side == 0 {
        return Err(FitError::NoRoom {
            cells: capacity.cells,
        });
    }
    let (x0, y0, x1, y1) = free_bounds(map).ok_or(FitError::NoFreeCell)?;
    // The crop, with a margin of one cell where the map has it.
    let (cx0, cy0) = (x0.saturating_sub(1), y0.saturating_sub(1));
    let cx1 = x1.saturating_add(1).min(map.width - 1);
    let cy1 = y1.saturating_add(1).min(map.height - 1);
    let (cw, ch) = (cx1 - cx0 + 1, cy1 - cy0 + 1);
    let window = |ox: i32, oy: i32, k: u16, w: u16, h: u16| Fitted {
        factor: k,
        origin: (ox, oy),
        map: coarse(map, (ox, oy), k, w, h),
        metric: metric.map(|f| window_frame(&f, (ox, oy), k, w, h)),
        original_size: (map.width, map.height),
    };
    if fits_size(cw, ch, capacity) {
        return Ok(Some(window(cx0.into(), cy0.into(), 1, cw, ch)));
    }
    // Without the margin, if that is what fits.
    let (tw, th) = (x1 - x0 + 1, y1 - y0 + 1);
    if fits_size(tw, th, capacity) {
        return Ok(Some(window(x0.into(), y0.into(), 1, tw, th)));
    }
    // The smallest factor whose grid from the free area's corner fits; a grid shifted by an
    // offset may need one more coarse cell a side, and is tried only if it fits too. If no offset
    // keeps every endpoint free at that factor, the next factor is tried before refusing.
    let sides = |k: u16, dx: i32, dy: i32| {
        let side = |t: u16, d: i32| {
            let n = (i32::from(t) + d + i32::from(k) - 1) / i32::from(k);
            u16::try_from(n).unwrap_or(u16::MAX)
        };
        (side(tw, dx), side(th, dy))
    };
    let k = (2..=tw.max(th))
        .find(|&k| {
            let (w, h) = sides(k, 0, 0);
            fits_size(w, h, capacity)
        })
        .ok_or(FitError::NoRoom {
            cells: capacity.cells,
        })?;
    for k in [k, k.saturating_add(1)] {
        let ki = i32::from(k);
        for (dx, dy) in offsets(k) {
            let (w, h) = sides(k, dx, dy);
            if !fits_size(w, h, capacity) {
                continue;
            }
            let (ox, oy) = (i32::from(x0) - dx, i32::from(y0) - dy);
            let free = |p: &Point| {
                let c = to_coarse((ox, oy), k, *p);
                block_free(map, (ox + i32::from(c.x) * ki, oy + i32::from(c.y) * ki), k)
            };
            if endpoints.iter().all(free) {
                return Ok(Some(window(ox, oy, k, w, h)));
            }
        }
    }
    let ki = i32::from(k);
    // Name the first endpoint that no offset keeps free (the start, if both).
    let lost = endpoints
        .iter()
        .enumerate()
        .find(|(_, p)| {
            offsets(k).all(|(dx, dy)| {
                let o = (i32::from(x0) - dx, i32::from(y0) - dy);
                let c = to_coarse(o, k, **p);
                !block_free(
                    map,
                    (o.0 + i32::from(c.x) * ki, o.1 + i32::from(c.y) * ki),
                    k,
                )
            })
        })
        .or_else(|| endpoints.iter().enumerate().next());
    let (i, p) = lost.map_or((0, Point::new(0, 0)), |(i, p)| (i, *p));
    Err(FitError::EndpointLost {
        which: if i % 2 == 0 { "start" } else { "goal" },
        x: p.x,
        y: p.y,
        width: tw,
        height: th,
        factor: k,
        size: metric.map_or_else(String::new, |f| {
            format!(" ({} m)", super::round_um(f.resolution * f64::from(k)))
        }),
        cells: capacity.cells,
        max_side: capacity.max_side,
    })
}

/// Offsets of the coarse grid's corner from the free area's corner, nearest first: `(0, 0)`, then
/// the rest of `0..k` x `0..k` (at most 64 of them: beyond, every `k / 8`-th).
fn offsets(k: u16) -> impl Iterator<Item = (i32, i32)> {
    let step = usize::from(k.div_ceil(8)).max(1);
    let k = i32::from(k);
    (0..k)
        .step_by(step)
        .flat_map(move |dy| (0..k).step_by(step).map(move |dx| (dx, dy)))
}

/// The fitted cell of original cell `p` for a grid with corner `origin` and factor `k`.
fn to_coarse(origin: (i32, i32), k: u16, p: Point) -> Point {
    let k = i32::from(k);
    let c = |v: u16, o: i32| u16::try_from((i32::from(v) - o).max(0) / k).unwrap_or(u16::MAX);
    Point::new(c(p.x, origin.0), c(p.y, origin.1))
}

/// True if the `k x k` block of original cells at `corner` is free (cells outside the map are
/// blocked).
fn block_free(map: &Map, corner: (i32, i32), k: u16) -> bool {
    let k = i32::from(k);
    (0..k).all(|dy| {
        (0..k).all(|dx| {
            let (x, y) = (corner.0 + dx, corner.1 + dy);
            match (u16::try_from(x), u16::try_from(y)) {
                (Ok(x), Ok(y)) => !map.is_blocked(Point::new(x, y)),
                _ => false,
            }
        })
    })
}

/// The `w x h` map of `k x k` blocks from `origin` (a block is blocked if any cell is).
fn coarse(map: &Map, origin: (i32, i32), k: u16, w: u16, h: u16) -> Map {
    let ki = i32::from(k);
    Map::from_fn(w, h, |x, y| {
        !block_free(
            map,
            (origin.0 + i32::from(x) * ki, origin.1 + i32::from(y) * ki),
            k,
        )
    })
}

/// The metric frame of the `w x h` fitted map whose cell `(0, 0)` starts at original cell
/// `origin`, `k` original cells a side: its lower-left corner is the original point at column
/// `origin.0`, `k * h` rows below row `origin.1`.
fn window_frame(f: &MapFrame, origin: (i32, i32), k: u16, w: u16, h: u16) -> MapFrame {
    let r = f.resolution;
    let lx = f64::from(origin.0) * r;
    let ly = (f64::from(f.height) - f64::from(origin.1) - f64::from(k) * f64::from(h)) * r;
    let (s, c) = f.yaw.sin_cos();
    MapFrame {
        resolution: r * f64::from(k),
        origin: [f.origin[0] + c * lx - s * ly, f.origin[1] + s * lx + c * ly],
        yaw: f.yaw,
        width: w,
        height: h,
    }
}

impl Fitted {
    /// The fitted map of `map` (the original map, changed since: `ohaca ros`'s map updates)
    /// through the same window: same corner, factor and sides, so cells keep their places and
    /// only the blocks whose cells changed differ.
    pub fn refresh(&self, map: &Map) -> Map {
        coarse(
            map,
            self.origin,
            self.factor,
            self.map.width,
            self.map.height,
        )
    }

    /// The fitted cell that holds original cell `p`, if the window covers it.
    pub fn cell_inside(&self, p: Point) -> Option<Point> {
        let k = i32::from(self.factor);
        let (dx, dy) = (
            i32::from(p.x) - self.origin.0,
            i32::from(p.y) - self.origin.1,
        );
        if dx < 0 || dy < 0 {
            return None;
        }
        let c = Point::new(u16::try_from(dx / k).ok()?, u16::try_from(dy / k).ok()?);
        (c.x < self.map.width && c.y < self.map.height).then_some(c)
    }

    /// The fitted cell that holds original cell `p`.
    pub fn cell(&self, p: Point) -> Point {
        to_coarse(self.origin, self.factor, p)
    }

    /// The original cell at the centre of fitted cell `c` (for `factor` 1: the same cell, moved
    /// back by the crop), clamped to the original map.
    pub fn original(&self, c: Point) -> Point {
        let k = i32::from(self.factor);
        let at = |v: u16, o: i32, n: u16| {
            let x = o + i32::from(v) * k + k / 2;
            u16::try_from(x.clamp(0, i32::from(n.max(1)) - 1)).unwrap_or(0)
        };
        Point::new(
            at(c.x, self.origin.0, self.original_size.0),
            at(c.y, self.origin.1, self.original_size.1),
        )
    }

    /// One line for the user: what was cropped and resampled to what (`name` the map file,
    /// `board` and `capacity` the device's).
    pub fn note(&self, name: &str, board: &str, capacity: &Capacity) -> String {
        let (w0, h0) = self.original_size;
        let k = self.factor;
        let what = if k == 1 {
            "cropped to its free area at full resolution".to_string()
        } else {
            let size = self
                .metric
                .map_or_else(String::new, |f| format!(" ({} m)", f.cell_size_m()));
            format!("cropped to its free area and resampled, {k}x{k} cells per cell{size}")
        };
        format!(
            "{name}: {w0}x{h0} cells do not fit {board} ({} cells, sides up to {}); {what}: \
             {}x{} cells from cell ({}, {}); start, goal and output are given in the original \
             map's cells",
            capacity.cells,
            capacity.max_side,
            self.map.width,
            self.map.height,
            self.origin.0,
            self.origin.1,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn capacity(cells: u32, max_side: u16) -> Capacity {
        Capacity {
            cells,
            max_side,
            max_steps: 1023,
            max_chunk: 128,
            max_request: 256,
            plan_queue: 4,
            tick_hz: 1_000_000,
            window: 8,
            window_bytes: 1024,
        }
    }

    /// A `side x side` map, all blocked (unknown) but a free `known x known` square at `at`.
    fn mostly_unknown(side: u16, known: u16, at: u16) -> Map {
        Map::from_fn(side, side, |x, y| {
            !((at..at + known).contains(&x) && (at..at + known).contains(&y))
        })
    }

    #[test]
    fn maps_that_fit_are_sent_as_they_are() {
        let map = Map::from_fn(100, 75, |_, _| false);
        assert_eq!(fit(&map, None, &capacity(7500, 100), &[]), Ok(None));
        // Any shape within cells and side.
        let tall = Map::from_fn(75, 100, |_, _| false);
        assert!(fits(&tall, &capacity(7500, 100)));
        assert!(!fits(&tall, &capacity(7500, 99)));
        assert!(!fits(&tall, &capacity(7499, 100)));
    }

    #[test]
    fn a_sandbox_with_a_small_known_area_is_cropped_not_resampled() {
        // The Nav2 TurtleBot sandbox's shape: 384 x 384, about 80 x 80 known.
        let map = mostly_unknown(384, 80, 150);
        let (s, g) = (Point::new(151, 151), Point::new(228, 229));
        let f = fit(&map, None, &capacity(65_536, 4096), &[s, g])
            .unwrap()
            .unwrap();
        assert_eq!(f.factor, 1);
        assert_eq!((f.map.width, f.map.height), (82, 82), "80 + a margin");
        assert_eq!(f.origin, (149, 149));
        for p in [s, g] {
            let c = f.cell(p);
            assert!(!f.map.is_blocked(c));
            assert_eq!(f.original(c), p, "full resolution: the same cell back");
        }
        // Every cell of the crop is the original's.
        for y in 0..82 {
            for x in 0..82 {
                let c = Point::new(x, y);
                assert_eq!(f.map.is_blocked(c), map.is_blocked(f.original(c)));
            }
        }
    }

    #[test]
    fn the_crop_keeps_the_metric_frame() {
        let map = mostly_unknown(384, 80, 150);
        let frame = MapFrame {
            resolution: 0.05,
            origin: [-10.0, -10.0],
            yaw: 0.3,
            width: 384,
            height: 384,
        };
        let f = fit(&map, Some(frame), &capacity(65_536, 4096), &[])
            .unwrap()
            .unwrap();
        let m = f.metric.unwrap();
        for p in [Point::new(150, 150), Point::new(229, 200)] {
            let a = frame.to_metres(p);
            let b = m.to_metres(f.cell(p));
            assert!(
                (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9,
                "{a:?} {b:?}"
            );
        }
    }

    #[test]
    fn resampling_is_conservative_and_keeps_free_endpoints_free() {
        // 200 x 200, free but a grid of single obstacles every 16 cells: must go to 1,024 cells
        // (7 x 7 cells per cell).
        let map = Map::from_fn(200, 200, |x, y| x % 16 == 3 && y % 16 == 3);
        // A start right next to an obstacle: at (0, 0) offsets its block holds (3, 3).
        let (s, g) = (Point::new(4, 3), Point::new(190, 190));
        let cap = capacity(1024, 4096);
        let f = fit(&map, None, &cap, &[s, g]).unwrap().unwrap();
        assert_eq!(f.factor, 7);
        assert_ne!(
            f.origin,
            (0, 0),
            "the grid from (0, 0) puts (3, 3) in the start's cell"
        );
        assert!(fits(&f.map, &cap));
        for p in [s, g] {
            assert!(!f.map.is_blocked(f.cell(p)), "{p:?} lost");
        }
        // Conservative: a free coarse cell covers only free original cells.
        let k = i32::from(f.factor);
        for y in 0..f.map.height {
            for x in 0..f.map.width {
                if f.map.is_blocked(Point::new(x, y)) {
                    continue;
                }
                let (cx, cy) = (f.origin.0 + i32::from(x) * k, f.origin.1 + i32::from(y) * k);
                for dy in 0..k {
                    for dx in 0..k {
                        let p = Point::new((cx + dx) as u16, (cy + dy) as u16);
                        assert!(!map.is_blocked(p), "{p:?} under free coarse ({x}, {y})");
                    }
                }
            }
        }
    }

    #[test]
    fn an_endpoint_no_grid_keeps_free_is_refused_with_what_to_do() {
        // Obstacles on every other cell of every other row: any 2 x 2 block holds one, so a
        // map that must be resampled loses every free cell near them.
        let map = Map::from_fn(100, 100, |x, y| x % 2 == 1 && y % 2 == 1);
        let e = fit(&map, None, &capacity(1024, 4096), &[Point::new(0, 0)]).unwrap_err();
        let FitError::EndpointLost { which, factor, .. } = &e else {
            panic!("{e}");
        };
        assert_eq!((*which, *factor), ("start", 4));
        let msg = e.to_string();
        for want in ["1024 cells", "--cell", "--inflate", "start 0,0"] {
            assert!(msg.contains(want), "{msg}");
        }
    }

    #[test]
    fn nothing_fits_a_device_without_cells() {
        let map = Map::from_fn(10, 10, |_, _| false);
        assert!(matches!(
            fit(&map, None, &capacity(0, 0), &[]),
            Err(FitError::NoRoom { .. })
        ));
        let full = Map::from_fn(10, 10, |_, _| true);
        assert_eq!(
            fit(&full, None, &capacity(4, 4), &[]),
            Err(FitError::NoFreeCell)
        );
    }

    #[test]
    fn resampled_cells_follow_the_metric_frame_and_the_note_is_readable() {
        // 100x75 cells of 0.1 m into 1,024 cells: 0.1 * 3 is 0.30000000000000004 in f64.
        let fine = MapFrame {
            resolution: 0.1,
            origin: [-1.0, -2.0],
            yaw: 0.0,
            width: 100,
            height: 75,
        };
        let map = Map::from_fn(100, 75, |_, _| false);
        let cap = capacity(1024, 4096);
        let f = fit(&map, Some(fine), &cap, &[]).unwrap().unwrap();
        assert_eq!(f.factor, 3);
        assert!(fits(&f.map, &cap));
        let coarse = f.metric.unwrap();
        // Every fine cell's centre lies in the coarse cell it is mapped to, and a coarse cell's
        // original is a fine cell inside it.
        for y in 0..75 {
            for x in 0..100 {
                let p = Point::new(x, y);
                assert_eq!(coarse.cell(fine.to_metres(p)), Some(f.cell(p)), "{p:?}");
            }
        }
        let c = Point::new(3, 2);
        assert_eq!(f.cell(f.original(c)), c);
        let note = f.note("lab.yaml", "qemu", &cap);
        assert!(note.contains("3x3 cells per cell (0.3 m)"), "{note}");
        assert!(note.contains("1024 cells, sides up to 4096"), "{note}");
    }
}
