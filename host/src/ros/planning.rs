//! The planning side of `ohaca ros`, without DDS: the map as it arrived (`/map`, changed by
//! `/map_updates`), the same map inflated and fitted to the backend, and plans between poses in
//! metres, answered in the map's frame.
//!
//! - **Map**: an `OccupancyGrid` is classified ([`grid_map`]), inflated by `--inflate` metres on
//!   its own cells ([`inflate`]), and, on a device, fitted to what it holds ([`fit`]: cropped to
//!   the free area, then resampled only if needed, keeping start and goal free; the same as
//!   `ohaca send`). It goes to the backend at once; a map the backend cannot take then (a device
//!   unreachable) is kept and sent at the next plan, and so is the map after an update the
//!   backend failed to take.
//! - **Updates**: an `OccupancyGridUpdate` changes the grid; inflation is recomputed, the fitted
//!   map refreshed through the same window ([`Fitted::refresh`]), and only the cells that differ
//!   from what the backend holds are sent: one `SetRect` when they fill a rectangle with one
//!   value, `SetCells` otherwise. The backend keeps its colony for a warm replan.
//! - **Plans**: start and goal are checked on the map as it arrived (off the map, on an
//!   obstacle: [`PlanError`] with Nav2's error codes); a start or goal that the fitted map loses
//!   makes a new fit for them (uploaded again; that plan is cold). The device's cells go back to
//!   the original map, then to metres: the path runs from the start as given, through the
//!   waypoints' cell centres, to the goal as given.

use std::time::{Duration, Instant};

use ohaca::planner::Origin;
use ohaca::Point;

use super::backend::{Backend, BackendError};
use super::convert::{apply_update, grid_map, Occupancy01};
use super::msg::{error_code, OccupancyGrid, OccupancyGridUpdate};
use crate::link::MapCode;
use crate::map::{fit, fits, inflate, Fitted, Map, MapFrame};
use crate::replan::Planned;

/// The map as received and as sent.
struct Loaded {
    /// As classified, before inflation (updates change this).
    grid: Map,
    /// Inflated: what start and goal are checked on.
    map: Map,
    frame: MapFrame,
    frame_id: String,
    /// The window sent to the backend when the map did not fit it as it is.
    fitted: Option<Fitted>,
    /// What the backend holds (the fitted map, or `map`).
    sent: Map,
    /// Not on the backend (the upload failed, or an update did): sent whole at the next plan.
    pending: bool,
}

/// A plan, in the map's frame.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanOut {
    /// Start, waypoints, goal: metres in the map frame.
    pub points_m: Vec<[f64; 2]>,
    /// The waypoints in the original map's cells (start first).
    pub cells: Vec<Point>,
    /// The backend's answer (in its cells).
    pub planned: Planned,
    /// Where the path comes from: `cold`, `warm` (the backend kept its colony) or `reused`
    /// (the rest of the previous answer: no change since could shorten or block it).
    pub origin: Origin,
    /// From the request to the path.
    pub elapsed: Duration,
    /// The map frame's name.
    pub frame_id: String,
    /// Original cells per backend cell (1: full resolution).
    pub factor: u16,
    /// The backend map's sides.
    pub sent_size: (u16, u16),
    /// Start and goal in the backend's cells.
    pub ends: (Point, Point),
}

/// Why a plan failed, with Nav2's `ComputePathToPose` error code.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct PlanError {
    /// A [`error_code`] value.
    pub code: u16,
    /// In words.
    pub message: String,
}

impl PlanError {
    fn new(code: u16, message: impl Into<String>) -> Self {
        PlanError {
            code,
            message: message.into(),
        }
    }
}

impl From<BackendError> for PlanError {
    fn from(e: BackendError) -> Self {
        let code = match e {
            BackendError::Timeout(_) => error_code::TIMEOUT,
            BackendError::NoPath(_) => error_code::NO_VALID_PATH,
            _ => error_code::UNKNOWN,
        };
        PlanError::new(code, e.to_string())
    }
}

/// What a map or an update did, for the log (and `--gif`).
#[derive(Clone, Debug, PartialEq)]
pub struct MapNote {
    /// One line.
    pub text: String,
    /// Cells the backend got blocked (backend cells; updates only).
    pub blocked: Vec<Point>,
    /// Cells the backend got cleared.
    pub cleared: Vec<Point>,
}

/// See the module docs.
pub struct Planning {
    backend: Box<dyn Backend>,
    rule: Occupancy01,
    /// `--inflate`, metres.
    inflate_m: Option<f64>,
    loaded: Option<Loaded>,
    /// The last whole-map upload: seconds, and the map's bytes as coded for the wire.
    last_upload: Option<(f64, usize)>,
}

/// Cells of `a` and `b` (same sides) that differ, split into blocked in `b` and cleared in `b`.
fn diff(a: &Map, b: &Map) -> (Vec<Point>, Vec<Point>) {
    let (mut blocked, mut cleared) = (Vec::new(), Vec::new());
    for y in 0..b.height {
        for x in 0..b.width {
            let p = Point::new(x, y);
            match (a.is_blocked(p), b.is_blocked(p)) {
                (false, true) => blocked.push(p),
                (true, false) => cleared.push(p),
                _ => {}
            }
        }
    }
    (blocked, cleared)
}

/// The bounding rectangle of `cells` if they fill it exactly.
fn as_rect(cells: &[Point]) -> Option<(u16, u16, u16, u16)> {
    let x0 = cells.iter().map(|p| p.x).min()?;
    let x1 = cells.iter().map(|p| p.x).max()?;
    let y0 = cells.iter().map(|p| p.y).min()?;
    let y1 = cells.iter().map(|p| p.y).max()?;
    let (w, h) = (x1 - x0 + 1, y1 - y0 + 1);
    (usize::from(w) * usize::from(h) == cells.len()).then_some((x0, y0, w, h))
}

impl Planning {
    /// Planning on `backend` with the occupancy `rule` and `inflate_m` metres of inflation.
    pub fn new(backend: Box<dyn Backend>, rule: Occupancy01, inflate_m: Option<f64>) -> Self {
        Planning {
            backend,
            rule,
            inflate_m,
            loaded: None,
            last_upload: None,
        }
    }

    /// The backend, for the log.
    pub fn describe(&self) -> String {
        self.backend.describe()
    }

    /// The map frame's name, once a map arrived.
    pub fn frame_id(&self) -> Option<&str> {
        self.loaded.as_ref().map(|l| l.frame_id.as_str())
    }

    fn inflated(&self, grid: &Map, frame: &MapFrame) -> Map {
        match self.inflate_m {
            Some(r) if r > 0.0 => inflate(grid, r / frame.resolution),
            _ => grid.clone(),
        }
    }

    /// Fit `map` to the backend (keeping `ends` free), or `None` if it goes as it is.
    fn fitted(
        &mut self,
        map: &Map,
        frame: &MapFrame,
        ends: &[Point],
    ) -> Result<Option<Fitted>, PlanError> {
        let Some(cap) = self.backend.capacity()? else {
            return Ok(None);
        };
        if fits(map, &cap) {
            return Ok(None);
        }
        let f = fit(map, Some(*frame), &cap, ends)
            .map_err(|e| PlanError::new(error_code::UNKNOWN, format!("map: {e}")))?;
        if let Some(f) = &f {
            log::info!(
                "map {}x{} does not fit the device ({} cells, sides up to {}): sent {}x{} cells, \
                 {}x{} original cells per cell, from cell ({}, {})",
                map.width,
                map.height,
                cap.cells,
                cap.max_side,
                f.map.width,
                f.map.height,
                f.factor,
                f.factor,
                f.origin.0,
                f.origin.1
            );
        }
        Ok(f)
    }

    /// A new map (`/map`): classified, inflated, fitted and sent. A map the backend could not
    /// take is kept (the error says so) and sent at the next plan.
    pub fn set_grid(&mut self, g: &OccupancyGrid) -> Result<MapNote, PlanError> {
        let (grid, frame) = grid_map(g, &self.rule)
            .map_err(|e| PlanError::new(error_code::UNKNOWN, e.to_string()))?;
        let map = self.inflated(&grid, &frame);
        self.loaded = Some(Loaded {
            grid,
            sent: map.clone(),
            map,
            frame,
            frame_id: g.header.frame_id.clone(),
            fitted: None,
            pending: true,
        });
        let text = self.send(&[]).map_err(|e| {
            PlanError::new(
                e.code,
                format!("{e}; the map is kept and sent again at the next request"),
            )
        })?;
        Ok(MapNote {
            text,
            blocked: Vec::new(),
            cleared: Vec::new(),
        })
    }

    /// Fit the map to the backend (keeping `ends` free) and upload it.
    fn send(&mut self, ends: &[Point]) -> Result<String, PlanError> {
        let Some(l) = self.loaded.as_ref() else {
            return Err(PlanError::new(error_code::UNKNOWN, "no map"));
        };
        let (map, frame) = (l.map.clone(), l.frame);
        let fitted = self.fitted(&map, &frame, ends)?;
        let sent = fitted
            .as_ref()
            .map_or_else(|| map.clone(), |f| f.map.clone());
        let t0 = Instant::now();
        self.backend.upload(&sent)?;
        let secs = t0.elapsed().as_secs_f64();
        let bytes = MapCode::of(&sent).bytes().len();
        self.last_upload = Some((secs, bytes));
        let text = format!(
            "map {}x{} cells of {} m in frame `{}` sent to {} as {}x{} ({bytes} bytes coded) in \
             {secs:.3} s",
            map.width,
            map.height,
            frame.cell_size_m(),
            self.frame_id().unwrap_or(""),
            self.backend.describe(),
            sent.width,
            sent.height,
        );
        if let Some(l) = self.loaded.as_mut() {
            l.fitted = fitted;
            l.sent = sent;
            l.pending = false;
        }
        Ok(text)
    }

    /// A map update (`/map_updates`): see the module docs.
    pub fn update(&mut self, u: &OccupancyGridUpdate) -> Result<MapNote, PlanError> {
        let Some(l) = self.loaded.as_mut() else {
            return Err(PlanError::new(
                error_code::UNKNOWN,
                "a map update before any map: ignored",
            ));
        };
        let window = apply_update(&mut l.grid, u, &self.rule)
            .map_err(|e| PlanError::new(error_code::UNKNOWN, e.to_string()))?;
        let (grid, frame) = (l.grid.clone(), l.frame);
        let map = self.inflated(&grid, &frame);
        let Some(l) = self.loaded.as_mut() else {
            return Err(PlanError::new(error_code::UNKNOWN, "no map"));
        };
        let next = l
            .fitted
            .as_ref()
            .map_or_else(|| map.clone(), |f| f.refresh(&map));
        let (blocked, cleared) = diff(&l.sent, &next);
        l.map = map;
        l.sent = next;
        let pending = l.pending;
        let mut sent = Vec::new();
        for (cells, b) in [(&blocked, true), (&cleared, false)] {
            if cells.is_empty() || pending {
                continue;
            }
            let r = match as_rect(cells) {
                Some(r) => {
                    sent.push(format!("SetRect {}x{} at ({}, {})", r.2, r.3, r.0, r.1));
                    self.backend.set_rect(r, b)
                }
                None => {
                    sent.push(format!("SetCells {}", cells.len()));
                    self.backend.set_cells(cells, b)
                }
            };
            if let Err(e) = r {
                // What the device holds is unknown now: the whole map goes at the next plan.
                if let Some(l) = self.loaded.as_mut() {
                    l.pending = true;
                }
                return Err(PlanError::from(e));
            }
        }
        if pending {
            sent.push("kept for the next upload".into());
        }
        Ok(MapNote {
            text: format!(
                "map update {}x{} at ({}, {}): {} cells blocked, {} cleared on {}{}",
                window.2,
                window.3,
                window.0,
                window.1,
                blocked.len(),
                cleared.len(),
                self.backend.describe(),
                if sent.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", sent.join(", "))
                }
            ),
            blocked,
            cleared,
        })
    }

    /// Plan from `start` to `goal` (metres in the map frame), warm if the backend kept the
    /// colony of its last plan to this goal.
    pub fn plan(&mut self, start: [f64; 2], goal: [f64; 2]) -> Result<PlanOut, PlanError> {
        let t0 = Instant::now();
        let Some(l) = self.loaded.as_ref() else {
            return Err(PlanError::new(
                error_code::UNKNOWN,
                "no map yet: waiting for the map topic",
            ));
        };
        let frame = l.frame;
        let cell = |m: [f64; 2], what: &str, off: u16, occ: u16| -> Result<Point, PlanError> {
            let c = frame.cell(m).ok_or_else(|| {
                let e = frame.extent();
                PlanError::new(
                    off,
                    format!(
                        "{what} ({:.3}, {:.3}) is off the map (x {:.3}..{:.3}, y {:.3}..{:.3} \
                         before its yaw)",
                        m[0], m[1], e[0], e[1], e[2], e[3]
                    ),
                )
            })?;
            if l.map.is_blocked(c) {
                return Err(PlanError::new(
                    occ,
                    format!(
                        "{what} ({:.3}, {:.3}) is on an obstacle (cell {},{}{})",
                        m[0],
                        m[1],
                        c.x,
                        c.y,
                        if self.inflate_m.is_some() {
                            ", inflated"
                        } else {
                            ""
                        }
                    ),
                ));
            }
            Ok(c)
        };
        let s = cell(
            start,
            "start",
            error_code::START_OUTSIDE_MAP,
            error_code::START_OCCUPIED,
        )?;
        let g = cell(
            goal,
            "goal",
            error_code::GOAL_OUTSIDE_MAP,
            error_code::GOAL_OCCUPIED,
        )?;
        // The backend's cells; a fitted map that loses an endpoint is fitted again for it.
        let lost = |l: &Loaded| match &l.fitted {
            None => false,
            Some(f) => [s, g]
                .iter()
                .any(|&p| f.cell_inside(p).is_none_or(|c| f.map.is_blocked(c))),
        };
        if l.pending || lost(l) {
            let note = self.send(&[s, g])?;
            log::info!("{note}");
        }
        let Some(l) = self.loaded.as_ref() else {
            return Err(PlanError::new(error_code::UNKNOWN, "no map"));
        };
        let (bs, bg) = match &l.fitted {
            None => (s, g),
            Some(f) => match (f.cell_inside(s), f.cell_inside(g)) {
                (Some(a), Some(b)) => (a, b),
                _ => {
                    return Err(PlanError::new(
                        error_code::UNKNOWN,
                        "start or goal outside the map sent to the device",
                    ))
                }
            },
        };
        let fitted = l.fitted.clone();
        let (frame_id, sent_size) = (l.frame_id.clone(), (l.sent.width, l.sent.height));
        let planned = self.backend.plan(bs, bg, true)?;
        let back = |c: Point| fitted.as_ref().map_or(c, |f| f.original(c));
        let mut cells: Vec<Point> = planned.waypoints.iter().map(|&c| back(c)).collect();
        if let Some(first) = cells.first_mut() {
            *first = s;
        }
        if let Some(last) = cells.last_mut() {
            *last = g;
        }
        let mut points_m: Vec<[f64; 2]> = cells.iter().map(|&c| frame.to_metres(c)).collect();
        if let Some(first) = points_m.first_mut() {
            *first = start;
        }
        if let Some(last) = points_m.last_mut() {
            *last = goal;
        }
        Ok(PlanOut {
            points_m,
            cells,
            origin: planned.origin,
            planned,
            elapsed: t0.elapsed(),
            frame_id,
            factor: fitted.as_ref().map_or(1, |f| f.factor),
            sent_size,
            ends: (bs, bg),
        })
    }

    /// The last whole-map upload: seconds, and the map's bytes as coded for the wire
    /// ([`MapCode`]; frames add a few per chunk).
    pub fn last_upload(&self) -> Option<(f64, usize)> {
        self.last_upload
    }

    /// The map as the backend holds it (for pictures of the drive).
    pub fn sent_map(&self) -> Option<&Map> {
        self.loaded.as_ref().map(|l| &l.sent)
    }
}

#[cfg(test)]
mod tests {
    use super::super::backend::HostBackend;
    use super::super::msg::{Header, MapMetaData, Point3, Pose, Quaternion, Time};
    use super::*;
    use ohaca::Params;

    /// A 20 x 10 grid of 0.1 m from (0, 0), free.
    fn grid() -> OccupancyGrid {
        OccupancyGrid {
            header: Header {
                stamp: Time::default(),
                frame_id: "map".into(),
            },
            info: MapMetaData {
                map_load_time: Time::default(),
                resolution: 0.1,
                width: 20,
                height: 10,
                origin: Pose {
                    position: Point3::default(),
                    orientation: Quaternion::default(),
                },
            },
            data: vec![0; 200],
        }
    }

    #[test]
    fn plans_errors_and_warm_replans() {
        let mut p = Planning::new(
            Box::new(HostBackend::new(Params::default())),
            Occupancy01::default(),
            None,
        );
        assert_eq!(
            p.plan([0.05, 0.5], [1.95, 0.5]).unwrap_err().code,
            error_code::UNKNOWN
        );
        p.set_grid(&grid()).unwrap();
        let out = p.plan([0.05, 0.55], [1.95, 0.55]).unwrap();
        assert!(!out.origin.is_warm());
        assert_eq!(out.points_m.first(), Some(&[0.05, 0.55]));
        assert_eq!(out.points_m.last(), Some(&[1.95, 0.55]));
        assert_eq!(out.frame_id, "map");
        // A wall across x = 1.0..1.1 (column 10), rows 0..9 (leaving the top row free).
        let u = OccupancyGridUpdate {
            header: Header::default(),
            x: 10,
            y: 0,
            width: 1,
            height: 9,
            data: vec![100; 9],
        };
        let note = p.update(&u).unwrap();
        assert!(note.text.contains("SetRect 1x9"), "{}", note.text);
        let again = p.plan([0.05, 0.55], [1.95, 0.55]).unwrap();
        assert!(again.origin.is_warm(), "the replan keeps the colony");
        assert!(again.cells.iter().all(|c| c.x != 10 || c.y == 0));
        for (what, s, g, code) in [
            (
                "off",
                [-1.0, 0.5],
                [1.95, 0.5],
                error_code::START_OUTSIDE_MAP,
            ),
            ("off", [0.05, 0.5], [5.0, 0.5], error_code::GOAL_OUTSIDE_MAP),
            ("on", [1.05, 0.5], [1.95, 0.5], error_code::START_OCCUPIED),
            ("on", [0.05, 0.5], [1.05, 0.3], error_code::GOAL_OCCUPIED),
        ] {
            let e = p.plan(s, g).unwrap_err();
            assert_eq!(e.code, code, "{e}");
            assert!(e.message.contains(what), "{e}");
        }
    }

    /// The host core posing as a device that holds `cap`.
    struct Small(HostBackend, ohaca::protocol::Capacity);

    impl Backend for Small {
        fn describe(&self) -> String {
            "a small device".into()
        }
        fn capacity(&mut self) -> Result<Option<ohaca::protocol::Capacity>, BackendError> {
            Ok(Some(self.1))
        }
        fn upload(&mut self, map: &Map) -> Result<(), BackendError> {
            assert!(fits(map, &self.1), "{}x{}", map.width, map.height);
            self.0.upload(map)
        }
        fn set_rect(&mut self, r: (u16, u16, u16, u16), b: bool) -> Result<(), BackendError> {
            self.0.set_rect(r, b)
        }
        fn set_cells(&mut self, c: &[Point], b: bool) -> Result<(), BackendError> {
            self.0.set_cells(c, b)
        }
        fn plan(&mut self, s: Point, g: Point, w: bool) -> Result<Planned, BackendError> {
            self.0.plan(s, g, w)
        }
    }

    #[test]
    fn a_map_larger_than_the_device_is_resampled_and_answered_in_its_own_frame() {
        // 100 x 100 cells of 0.1 m with a wall; the device holds 1,024 cells: 4 x 4 per cell.
        let mut g = grid();
        g.info.width = 100;
        g.info.height = 100;
        g.data = (0..100 * 100)
            .map(|i| {
                if i % 100 == 50 && i / 100 < 80 {
                    100
                } else {
                    0
                }
            })
            .collect();
        let cap = ohaca::protocol::Capacity {
            cells: 1024,
            max_side: 4096,
            max_steps: 1023,
            max_chunk: 128,
            max_request: 256,
            plan_queue: 4,
            tick_hz: 1_000_000,
            window: 8,
            window_bytes: 1024,
        };
        let mut p = Planning::new(
            Box::new(Small(HostBackend::new(Params::default()), cap)),
            Occupancy01::default(),
            None,
        );
        let note = p.set_grid(&g).unwrap();
        assert!(note.text.contains("as 25x25"), "{}", note.text);
        let (s, goal) = ([0.25, 0.25], [9.75, 0.25]);
        let out = p.plan(s, goal).unwrap();
        assert_eq!(out.factor, 4);
        assert_eq!(out.points_m.first(), Some(&s));
        assert_eq!(out.points_m.last(), Some(&goal));
        // Every waypoint is a free cell of the original map, and the path goes over the wall.
        let (map, frame) = grid_map(&g, &Occupancy01::default()).unwrap();
        for m in &out.points_m {
            let c = frame.cell(*m).unwrap();
            assert!(!map.is_blocked(c), "{m:?}");
        }
        assert!(
            out.points_m.iter().any(|m| m[1] > 8.0),
            "{:?}",
            out.points_m
        );
        // An update reaches the device through the same window.
        let u = OccupancyGridUpdate {
            header: Header::default(),
            x: 0,
            y: 90,
            width: 40,
            height: 1,
            data: vec![100; 40],
        };
        let note = p.update(&u).unwrap();
        assert_eq!(note.blocked.len(), 10, "{}", note.text);
    }

    /// The host core behind a link that fails its first `fail` uploads.
    struct Flaky(HostBackend, usize);

    impl Backend for Flaky {
        fn describe(&self) -> String {
            "a flaky device".into()
        }
        fn capacity(&mut self) -> Result<Option<ohaca::protocol::Capacity>, BackendError> {
            Ok(None)
        }
        fn upload(&mut self, map: &Map) -> Result<(), BackendError> {
            if self.1 > 0 {
                self.1 -= 1;
                return Err(BackendError::Unreachable("cable out".into()));
            }
            self.0.upload(map)
        }
        fn set_rect(&mut self, r: (u16, u16, u16, u16), b: bool) -> Result<(), BackendError> {
            self.0.set_rect(r, b)
        }
        fn set_cells(&mut self, c: &[Point], b: bool) -> Result<(), BackendError> {
            self.0.set_cells(c, b)
        }
        fn plan(&mut self, s: Point, g: Point, w: bool) -> Result<Planned, BackendError> {
            self.0.plan(s, g, w)
        }
    }

    #[test]
    fn a_map_the_device_missed_is_sent_at_the_next_request() {
        let mut p = Planning::new(
            Box::new(Flaky(HostBackend::new(Params::default()), 2)),
            Occupancy01::default(),
            None,
        );
        let e = p.set_grid(&grid()).unwrap_err();
        assert!(e.message.contains("unreachable: cable out"), "{e}");
        assert!(e.message.contains("kept"), "{e}");
        // An update while it is not there changes the kept map only.
        let u = OccupancyGridUpdate {
            header: Header::default(),
            x: 10,
            y: 0,
            width: 1,
            height: 9,
            data: vec![100; 9],
        };
        assert!(p
            .update(&u)
            .unwrap()
            .text
            .contains("kept for the next upload"));
        let e = p.plan([0.05, 0.55], [1.95, 0.55]).unwrap_err();
        assert!(e.message.contains("device unreachable"), "{e}");
        let out = p.plan([0.05, 0.55], [1.95, 0.55]).unwrap();
        assert!(
            out.cells.iter().all(|c| c.x != 10 || c.y == 0),
            "the update is in"
        );
    }

    #[test]
    fn rectangles_and_scattered_cells() {
        let c = |x, y| Point::new(x, y);
        assert_eq!(as_rect(&[c(1, 1), c(2, 1)]), Some((1, 1, 2, 1)));
        assert_eq!(as_rect(&[c(1, 1), c(2, 2)]), None);
        assert_eq!(as_rect(&[]), None);
    }
}
