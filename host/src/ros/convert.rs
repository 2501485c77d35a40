//! Conversions between ROS messages and the planner's cells: an `OccupancyGrid` becomes a
//! [`Map`] and its [`MapFrame`] with the same occupancy rule as a `map_server` file
//! ([`RosMeta::classify`] in `raw` mode: the value is the occupancy in percent, above
//! `occupied_thresh` blocked, below `free_thresh` free, anything else and -1 unknown, which
//! `--unknown` resolves); an `OccupancyGridUpdate` changes a window of it; poses are metres in
//! the map frame; a path of cells becomes a `nav_msgs/Path` with orientations along it.
//!
//! ROS grids count rows from the origin upwards (row 0 is the lowest), the planner from the top
//! (row 0 is the highest): ROS cell `(i, j)` is planner cell `(i, height - 1 - j)`, as for a
//! `map_server` image, whose first row is the top.

use ohaca::Point;

use super::msg::{
    Header, OccupancyGrid, OccupancyGridUpdate, Point3, Pose, PoseStamped, Quaternion, RosPath,
    Time,
};
use crate::map::{Map, MapFrame, Mode, Occupancy, RosMeta, Unknown, MAX_SIDE};

/// How occupancy values become free and blocked cells (`map_server`'s thresholds and
/// `--unknown`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Occupancy01 {
    /// Occupancy above this (0..=1) is blocked.
    pub occupied_thresh: f64,
    /// Occupancy below this (0..=1) is free.
    pub free_thresh: f64,
    /// What unknown cells become.
    pub unknown: Unknown,
}

impl Default for Occupancy01 {
    fn default() -> Self {
        Occupancy01 {
            occupied_thresh: 0.65,
            free_thresh: 0.196,
            unknown: Unknown::Blocked,
        }
    }
}

impl Occupancy01 {
    /// True if a cell of value `v` (-1 unknown, 0..=100 percent; anything else unknown) is
    /// blocked.
    pub fn blocked(&self, v: i8) -> bool {
        let meta = RosMeta {
            image: std::path::PathBuf::new(),
            resolution: 1.0,
            origin: [0.0; 3],
            negate: false,
            occupied_thresh: self.occupied_thresh,
            free_thresh: self.free_thresh,
            mode: Mode::Raw,
        };
        let class = if v < 0 {
            Occupancy::Unknown
        } else {
            meta.classify(f64::from(v), 255)
        };
        match class {
            Occupancy::Occupied => true,
            Occupancy::Free => false,
            Occupancy::Unknown => self.unknown == Unknown::Blocked,
        }
    }
}

/// Why an `OccupancyGrid` or an update cannot be applied.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ConvertError {
    /// A side of the grid is 0 or over [`MAX_SIDE`].
    #[error("map {what} {value} is not in 1..={MAX_SIDE}")]
    Side {
        /// `width` or `height`.
        what: &'static str,
        /// The side given.
        value: u32,
    },
    /// The grid's or the update's data is not width x height cells.
    #[error("{what} data has {len} cells, but {width}x{height} = {cells}")]
    Data {
        /// `map` or `update`.
        what: &'static str,
        /// Cells of data.
        len: usize,
        /// The width given.
        width: u32,
        /// The height given.
        height: u32,
        /// Their product.
        cells: usize,
    },
    /// The resolution is not a positive number.
    #[error("map resolution {0} is not a positive number")]
    Resolution(f32),
    /// The origin is not finite.
    #[error("map origin is not finite")]
    Origin,
    /// The update's window misses the map.
    #[error(
        "update window {width}x{height} at ({x}, {y}) is off the {map_width}x{map_height} map"
    )]
    OffMap {
        /// The window's width.
        width: u32,
        /// The window's height.
        height: u32,
        /// Its first column.
        x: i32,
        /// Its first row.
        y: i32,
        /// The map's width.
        map_width: u16,
        /// The map's height.
        map_height: u16,
    },
    /// A cell of the window is off the map.
    #[error("cell ({}, {}) is off the map", .0.x, .0.y)]
    Cell(Point),
}

/// The planner's map and the metric frame of an `OccupancyGrid`, or why it cannot be one.
pub fn grid_map(g: &OccupancyGrid, rule: &Occupancy01) -> Result<(Map, MapFrame), ConvertError> {
    let (w, h) = (g.info.width, g.info.height);
    let side = |value: u32, what: &'static str| -> Result<u16, ConvertError> {
        u16::try_from(value)
            .ok()
            .filter(|&s| s > 0 && usize::from(s) <= MAX_SIDE)
            .ok_or(ConvertError::Side { what, value })
    };
    let (w16, h16) = (side(w, "width")?, side(h, "height")?);
    let cells = usize::from(w16) * usize::from(h16);
    if g.data.len() != cells {
        return Err(ConvertError::Data {
            what: "map",
            len: g.data.len(),
            width: w,
            height: h,
            cells,
        });
    }
    // The decimal the publisher meant: map_server's 0.05 arrives as the float32 nearest to it,
    // 0.0500000007 in f64, and an inflation of 0.1 m must stay 2 cells, not 1.99999997.
    let res = decimal_f64(g.info.resolution);
    if !(res.is_finite() && res > 0.0) {
        return Err(ConvertError::Resolution(g.info.resolution));
    }
    let o = &g.info.origin;
    if !(o.position.x.is_finite() && o.position.y.is_finite()) {
        return Err(ConvertError::Origin);
    }
    let map = Map::from_fn(w16, h16, |x, y| {
        let row = usize::from(h16 - 1 - y);
        g.data
            .get(row * usize::from(w16) + usize::from(x))
            .is_none_or(|&v| rule.blocked(v))
    });
    let frame = MapFrame {
        resolution: res,
        origin: [o.position.x, o.position.y],
        yaw: o.orientation.yaw(),
        width: w16,
        height: h16,
    };
    Ok((map, frame))
}

/// The shortest decimal that reads back as `v` (Rust prints `f32`s that way), as an `f64`.
pub fn decimal_f64(v: f32) -> f64 {
    v.to_string().parse().unwrap_or(f64::NAN)
}

/// Apply an `OccupancyGridUpdate` to `map` (the grid before inflation): the window's cells take
/// the update's values. Returns the window in planner cells `(x, y, width, height)` (clipped to
/// the map), or why the update is refused (data of the wrong size, a window off the map).
pub fn apply_update(
    map: &mut Map,
    u: &OccupancyGridUpdate,
    rule: &Occupancy01,
) -> Result<(u16, u16, u16, u16), ConvertError> {
    let n = usize::try_from(u64::from(u.width) * u64::from(u.height)).unwrap_or(usize::MAX);
    if u.data.len() != n {
        return Err(ConvertError::Data {
            what: "update",
            len: u.data.len(),
            width: u.width,
            height: u.height,
            cells: n,
        });
    }
    let (mw, mh) = (i64::from(map.width), i64::from(map.height));
    let (x0, y0) = (i64::from(u.x), i64::from(u.y));
    let (x1, y1) = (x0 + i64::from(u.width), y0 + i64::from(u.height));
    let (cx0, cy0, cx1, cy1) = (x0.max(0), y0.max(0), x1.min(mw), y1.min(mh));
    if cx0 >= cx1 || cy0 >= cy1 {
        return Err(ConvertError::OffMap {
            width: u.width,
            height: u.height,
            x: u.x,
            y: u.y,
            map_width: map.width,
            map_height: map.height,
        });
    }
    for j in cy0..cy1 {
        for i in cx0..cx1 {
            let k = usize::try_from((j - y0) * i64::from(u.width) + (i - x0)).unwrap_or(0);
            let v = u.data.get(k).copied().unwrap_or(-1);
            let p = Point::new(
                u16::try_from(i).unwrap_or(0),
                u16::try_from(mh - 1 - j).unwrap_or(0),
            );
            map.set(p, rule.blocked(v))
                .map_err(|_| ConvertError::Cell(p))?;
        }
    }
    let cell = |v: i64| u16::try_from(v).unwrap_or(0);
    // ROS rows cy0..cy1 are planner rows mh - cy1 ..= mh - 1 - cy0.
    Ok((cell(cx0), cell(mh - cy1), cell(cx1 - cx0), cell(cy1 - cy0)))
}

/// The position of a pose, in metres (x, y), if finite.
pub fn position(p: &Pose) -> Option<[f64; 2]> {
    let [x, y] = [p.position.x, p.position.y];
    (x.is_finite() && y.is_finite()).then_some([x, y])
}

/// A `nav_msgs/Path` through `points` (metres, start first): each pose faces the next point;
/// the last takes `goal_yaw`.
pub fn ros_path(points: &[[f64; 2]], goal_yaw: f64, frame_id: &str, stamp: Time) -> RosPath {
    let header = Header {
        stamp,
        frame_id: frame_id.to_string(),
    };
    let mut poses = Vec::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        let yaw = match points.get(i + 1) {
            Some(n) if (n[0] - p[0]).hypot(n[1] - p[1]) > 1e-9 => (n[1] - p[1]).atan2(n[0] - p[0]),
            Some(_) => poses
                .last()
                .map_or(goal_yaw, |q: &PoseStamped| q.pose.orientation.yaw()),
            None => goal_yaw,
        };
        poses.push(PoseStamped {
            header: header.clone(),
            pose: Pose {
                position: Point3 {
                    x: p[0],
                    y: p[1],
                    z: 0.0,
                },
                orientation: Quaternion::from_yaw(yaw),
            },
        });
    }
    RosPath { header, poses }
}

#[cfg(test)]
mod tests {
    use super::super::msg::MapMetaData;
    use super::*;

    fn grid(w: u32, h: u32, data: Vec<i8>) -> OccupancyGrid {
        OccupancyGrid {
            header: Header::default(),
            info: MapMetaData {
                map_load_time: Time::default(),
                resolution: 0.5,
                width: w,
                height: h,
                origin: Pose {
                    position: Point3 {
                        x: -1.0,
                        y: 2.0,
                        z: 0.0,
                    },
                    orientation: Quaternion::default(),
                },
            },
            data,
        }
    }

    #[test]
    fn thresholds_follow_map_server() {
        let r = Occupancy01::default();
        assert!(r.blocked(100) && r.blocked(66));
        assert!(!r.blocked(0) && !r.blocked(19));
        assert!(r.blocked(-1) && r.blocked(50), "unknown is blocked");
        let free = Occupancy01 {
            unknown: Unknown::Free,
            ..r
        };
        assert!(!free.blocked(-1) && !free.blocked(50) && free.blocked(100));
    }

    #[test]
    fn rows_are_flipped_and_the_origin_is_the_lower_left_cell() {
        // 3 x 2: the ROS row 0 (lowest) has an obstacle at column 2.
        let g = grid(3, 2, vec![0, 0, 100, 0, 0, 0]);
        let (map, frame) = grid_map(&g, &Occupancy01::default()).unwrap();
        assert!(map.is_blocked(Point::new(2, 1)), "the bottom row is y = 1");
        assert!(!map.is_blocked(Point::new(2, 0)));
        assert_eq!(frame.cell([-1.0 + 1.25, 2.25]), Some(Point::new(2, 1)));
        assert!(grid_map(&grid(3, 2, vec![0; 5]), &Occupancy01::default()).is_err());
        assert!(grid_map(&grid(0, 2, vec![]), &Occupancy01::default()).is_err());
        let mut bad = grid(1, 1, vec![0]);
        bad.info.resolution = f32::NAN;
        assert!(grid_map(&bad, &Occupancy01::default()).is_err());
    }

    #[test]
    fn a_float32_resolution_is_the_decimal_it_stands_for() {
        assert_eq!(decimal_f64(0.05), 0.05);
        assert_eq!(decimal_f64(0.1), 0.1);
        let (_, frame) = grid_map(&grid(1, 1, vec![0]), &Occupancy01::default()).unwrap();
        assert_eq!(frame.resolution, 0.5);
    }

    #[test]
    fn updates_change_their_window_only() {
        let g = grid(4, 3, vec![0; 12]);
        let rule = Occupancy01::default();
        let (mut map, _) = grid_map(&g, &rule).unwrap();
        let u = OccupancyGridUpdate {
            header: Header::default(),
            x: 1,
            y: 0,
            width: 2,
            height: 1,
            data: vec![100, 100],
        };
        assert_eq!(apply_update(&mut map, &u, &rule), Ok((1, 2, 2, 1)));
        let blocked: Vec<Point> = (0..3)
            .flat_map(|y| (0..4).map(move |x| Point::new(x, y)))
            .filter(|&p| map.is_blocked(p))
            .collect();
        assert_eq!(blocked, vec![Point::new(1, 2), Point::new(2, 2)]);
        // Clipped at the map's edge; refused off the map or with the wrong data size.
        let edge = OccupancyGridUpdate {
            x: 3,
            y: 2,
            width: 2,
            height: 2,
            data: vec![100; 4],
            ..u.clone()
        };
        assert_eq!(apply_update(&mut map, &edge, &rule), Ok((3, 0, 1, 1)));
        let off = OccupancyGridUpdate { x: 9, ..u.clone() };
        assert!(apply_update(&mut map, &off, &rule).is_err());
        let short = OccupancyGridUpdate { data: vec![0], ..u };
        assert!(apply_update(&mut map, &short, &rule).is_err());
    }

    #[test]
    fn poses_face_the_next_point() {
        let p = ros_path(
            &[[0.0, 0.0], [1.0, 1.0], [1.0, 2.0]],
            0.3,
            "map",
            Time::default(),
        );
        assert_eq!(p.poses.len(), 3);
        let yaw = |i: usize| p.poses[i].pose.orientation.yaw();
        assert!((yaw(0) - std::f64::consts::FRAC_PI_4).abs() < 1e-9);
        assert!((yaw(1) - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
        assert!((yaw(2) - 0.3).abs() < 1e-9);
        assert_eq!(p.header.frame_id, "map");
    }
}
