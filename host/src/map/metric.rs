//! [`MapFrame`]: the metric frame of a map, where its cells are in metres (ROS's "map frame";
//! not the wire protocol's COBS frame).
//!
//! ROS `map_server` maps say how big a pixel is (`resolution`, metres per cell) and where the
//! **lower-left** pixel is (`origin`: x, y and a yaw, in the map frame, y pointing up). The
//! planner counts rows from the **top** (row 0 is the first image row). So cell `(x, y)` of a map
//! `H` rows high has its centre at
//!
//! ```text
//! local = ((x + 0.5) * resolution, (H - 1 - y + 0.5) * resolution)
//! metres = origin + R(yaw) * local
//! ```
//!
//! and [`MapFrame::cell`] inverts that: a point in metres belongs to the cell whose square contains
//! it (a point on a shared edge belongs to the cell to its right and above, in the map's own
//! axes, up to a billionth of a cell of rounding). Maps without a resolution (Moving AI, text grids, plain images) have no frame: their
//! positions are cells only.

use ohaca::Point;

/// A map's placement in metres. See the module docs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapFrame {
    /// Metres per cell (> 0).
    pub resolution: f64,
    /// Position of the lower-left corner of the lower-left cell, in metres.
    pub origin: [f64; 2],
    /// Rotation of the map's x axis, counter-clockwise, in radians (ROS's origin yaw).
    pub yaw: f64,
    /// Columns of the grid.
    pub width: u16,
    /// Rows of the grid.
    pub height: u16,
}

impl MapFrame {
    /// The centres of cells given as `[x, y]`, in metres rounded to a micrometre (what the
    /// reports print as `waypoints_m`).
    pub fn points_m(&self, points: &[[u16; 2]]) -> Vec<[f64; 2]> {
        points
            .iter()
            .map(|&[x, y]| {
                let [mx, my] = self.to_metres(Point::new(x, y));
                [round_um(mx), round_um(my)]
            })
            .collect()
    }

    /// The centre of cell `p` in metres (`p` may lie outside the grid; it is extrapolated).
    pub fn to_metres(&self, p: Point) -> [f64; 2] {
        let lx = (f64::from(p.x) + 0.5) * self.resolution;
        let ly = (f64::from(self.height) - 1.0 - f64::from(p.y) + 0.5) * self.resolution;
        let (s, c) = self.yaw.sin_cos();
        [
            self.origin[0] + c * lx - s * ly,
            self.origin[1] + s * lx + c * ly,
        ]
    }

    /// The cell containing the point `m` (metres), or `None` if it is outside the grid or not
    /// finite.
    pub fn cell(&self, m: [f64; 2]) -> Option<Point> {
        let (dx, dy) = (m[0] - self.origin[0], m[1] - self.origin[1]);
        let (s, c) = self.yaw.sin_cos();
        // Rotate back by -yaw.
        let lx = c * dx + s * dy;
        let ly = -s * dx + c * dy;
        // A billionth of a cell of slack, so that a decimal edge like 2.05 with a resolution of
        // 0.05 lands on the cell it names despite rounding.
        const SLACK: f64 = 1e-9;
        let col = (lx / self.resolution + SLACK).floor();
        let row_up = (ly / self.resolution + SLACK).floor();
        let inside = |v: f64, n: u16| v.is_finite() && v >= 0.0 && v < f64::from(n);
        if !inside(col, self.width) || !inside(row_up, self.height) {
            return None;
        }
        // Both are whole numbers in 0..n <= 65535, so the casts are exact.
        let x = col as u16;
        let y = self.height - 1 - row_up as u16;
        Some(Point::new(x, y))
    }

    /// Metres per cell rounded to a micrometre, for messages: `0.3`, not the
    /// `0.30000000000000004` of `0.1 * 3`.
    pub fn cell_size_m(&self) -> f64 {
        round_um(self.resolution)
    }

    /// The map's extent in its own axes: `(x_min, x_max, y_min, y_max)` of the rectangle the
    /// cells cover, relative to the origin, before the yaw rotation — i.e. metres when the yaw is
    /// 0.
    pub fn extent(&self) -> [f64; 4] {
        [
            self.origin[0],
            self.origin[0] + f64::from(self.width) * self.resolution,
            self.origin[1],
            self.origin[1] + f64::from(self.height) * self.resolution,
        ]
    }
}

/// `v` rounded to a micrometre, so JSON and CSV show `1.25` rather than `1.2500000000000002`.
pub fn round_um(v: f64) -> f64 {
    let r = (v * 1e6).round() / 1e6;
    // Avoid printing "-0".
    if r == 0.0 {
        0.0
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(yaw: f64) -> MapFrame {
        MapFrame {
            resolution: 0.05,
            origin: [-1.0, 2.0],
            yaw,
            width: 40,
            height: 30,
        }
    }

    #[test]
    fn lower_left_cell_is_at_the_origin() {
        let f = frame(0.0);
        // The bottom row is y = height - 1.
        let m = f.to_metres(Point::new(0, 29));
        assert!((m[0] - (-1.0 + 0.025)).abs() < 1e-12);
        assert!((m[1] - (2.0 + 0.025)).abs() < 1e-12);
        // The top-left cell is height - 1 rows up.
        let m = f.to_metres(Point::new(0, 0));
        assert!((m[1] - (2.0 + 29.5 * 0.05)).abs() < 1e-12);
        assert_eq!(f.cell([-1.0, 2.0]), Some(Point::new(0, 29)));
        assert_eq!(
            f.cell([-1.0 + 0.0499, 2.0 + 0.0499]),
            Some(Point::new(0, 29))
        );
        assert_eq!(f.cell([-1.0 + 0.05, 2.0 + 0.05]), Some(Point::new(1, 28)));
    }

    #[test]
    fn outside_is_none() {
        let f = frame(0.0);
        assert_eq!(f.cell([-1.001, 2.5]), None);
        assert_eq!(f.cell([-0.5, 1.999]), None);
        assert_eq!(
            f.cell([-1.0 + 2.0, 2.5]),
            None,
            "x = width * res is outside"
        );
        assert_eq!(
            f.cell([0.0, 2.0 + 1.5]),
            None,
            "y = height * res is outside"
        );
        assert_eq!(f.cell([f64::NAN, 2.5]), None);
        assert_eq!(f.cell([f64::INFINITY, 2.5]), None);
    }

    #[test]
    fn round_trip_every_cell() {
        for yaw in [0.0, 0.3, -2.0, std::f64::consts::FRAC_PI_2] {
            let f = frame(yaw);
            for y in 0..f.height {
                for x in 0..f.width {
                    let p = Point::new(x, y);
                    assert_eq!(f.cell(f.to_metres(p)), Some(p), "yaw {yaw} {p:?}");
                }
            }
        }
    }

    #[test]
    fn yaw_rotates_about_the_origin() {
        let f = frame(std::f64::consts::FRAC_PI_2);
        // Local +x becomes +y in the map frame.
        let m = f.to_metres(Point::new(0, 29));
        assert!((m[0] - (-1.0 - 0.025)).abs() < 1e-12, "{m:?}");
        assert!((m[1] - (2.0 + 0.025)).abs() < 1e-12, "{m:?}");
    }

    #[test]
    fn rounding() {
        assert_eq!(round_um(0.1 + 0.2), 0.3);
        assert_eq!(round_um(-0.0000001), 0.0);
        assert_eq!(round_um(1.25), 1.25);
        assert_eq!(round_um(-3.0000004), -3.0);
    }
}
