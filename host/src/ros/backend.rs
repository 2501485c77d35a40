//! What `ohaca ros` plans on: the host core ([`HostBackend`], `--host`) or a device over its
//! link ([`DeviceBackend`], `--tcp`/`--serial`, the same [`Link`] as `ohaca send` and `ohaca
//! replan`). Both take a whole map, cell changes (`SetRect`/`SetCells` on a device) and warm or
//! cold plans; failures are [`BackendError`]s the action's caller can be told about.
//!
//! A device that stops answering (a timeout, a closed connection) is reconnected at the next
//! request: the backend keeps a copy of the map it sent, so the reconnected device gets it again
//! (and plans cold once).

use ohaca::board::Board;
use ohaca::protocol::{Capacity, ErrorCode};
use ohaca::{Params, Point};

use crate::link::{DeviceInfo, Link, LinkError, Transport};
use crate::map::Map;
use crate::replan::{HostPlanner, Planned, Planner, ReplanError};

/// Why a backend call failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BackendError {
    /// The device cannot be reached (not connected, connection closed, i/o error).
    #[error("device unreachable: {0}")]
    Unreachable(String),
    /// The device did not answer in time.
    #[error("device timeout: {0}")]
    Timeout(String),
    /// The device is busy with other clients' plans.
    #[error("device busy: {0}")]
    Busy(String),
    /// There is no path (or no ant reached the goal).
    #[error("no path: {0}")]
    NoPath(String),
    /// The device refused the request for another reason (a map too large, a bad map, ...).
    #[error("device refused: {0}")]
    Refused(String),
}

/// Something that plans: see the module docs.
pub trait Backend {
    /// What it is, for the log: `host core`, or the device's board and address.
    fn describe(&self) -> String;
    /// The largest map it holds (`None`: any map, the host core).
    fn capacity(&mut self) -> Result<Option<Capacity>, BackendError>;
    /// Make `map` the active map (the previous colony is dropped).
    fn upload(&mut self, map: &Map) -> Result<(), BackendError>;
    /// Block or clear the rectangle `x, y, width, height` (on the map).
    fn set_rect(&mut self, rect: (u16, u16, u16, u16), blocked: bool) -> Result<(), BackendError>;
    /// Block or clear `cells` (on the map).
    fn set_cells(&mut self, cells: &[Point], blocked: bool) -> Result<(), BackendError>;
    /// Plan from `start` to `goal`; `warm` asks to keep the colony of the previous plan to the
    /// same goal.
    fn plan(&mut self, start: Point, goal: Point, warm: bool) -> Result<Planned, BackendError>;
}

/// The cells of a rectangle.
fn rect_cells((x, y, w, h): (u16, u16, u16, u16)) -> Vec<Point> {
    (y..y.saturating_add(h))
        .flat_map(|cy| (x..x.saturating_add(w)).map(move |cx| Point::new(cx, cy)))
        .collect()
}

/// The host core (bit-identical to the device's plans, [`HostPlanner`]).
pub struct HostBackend {
    planner: HostPlanner,
    /// `--board`: the board it plans as exactly, whose capacity it reports (maps larger than
    /// it takes are fitted as for a device).
    board: Option<Board>,
}

impl HostBackend {
    /// The core with `params`, planning as [`HostPlanner::new`] does (the STM32F411's layout,
    /// heap storage on maps larger than its arena; any map).
    pub fn new(params: Params) -> Self {
        HostBackend {
            planner: HostPlanner::new(params),
            board: None,
        }
    }

    /// The core with `params`, planning exactly as `board` does (`--board`).
    pub fn on(params: Params, board: Board) -> Self {
        HostBackend {
            planner: HostPlanner::on(params, board),
            board: Some(board),
        }
    }
}

impl Backend for HostBackend {
    fn describe(&self) -> String {
        match self.board {
            Some(b) => format!("the host core as the {} board", b.name),
            None => "the host core".into(),
        }
    }
    fn capacity(&mut self) -> Result<Option<Capacity>, BackendError> {
        Ok(self.board.as_ref().map(crate::board::capacity))
    }
    fn upload(&mut self, map: &Map) -> Result<(), BackendError> {
        self.planner
            .set_map(map)
            .map_err(|e| BackendError::Refused(e.to_string()))
    }
    fn set_rect(&mut self, rect: (u16, u16, u16, u16), blocked: bool) -> Result<(), BackendError> {
        self.set_cells(&rect_cells(rect), blocked)
    }
    fn set_cells(&mut self, cells: &[Point], blocked: bool) -> Result<(), BackendError> {
        self.planner
            .change(cells, blocked)
            .map_err(|e| BackendError::Refused(e.to_string()))
    }
    fn plan(&mut self, start: Point, goal: Point, warm: bool) -> Result<Planned, BackendError> {
        self.planner.plan(start, goal, warm).map_err(|e| match e {
            // The core's own words start with "no path: " (not "no path: no path: ...").
            ReplanError::Core(ohaca::Error::NoPath) => {
                BackendError::NoPath("the goal is not reachable from the start".into())
            }
            e => BackendError::NoPath(e.to_string()),
        })
    }
}

/// Opens the link to the device (again).
pub type Connect<T> = Box<dyn FnMut() -> Result<Link<T>, LinkError> + Send>;

/// A device over its link.
pub struct DeviceBackend<T: Transport> {
    target: String,
    connect: Connect<T>,
    params: Params,
    link: Option<(Link<T>, DeviceInfo)>,
    /// The map as the device holds it (or must get again after a reconnection).
    map: Option<Map>,
    /// The device lost its map (reconnected): send `map` before the next request.
    stale: bool,
}

impl<T: Transport> DeviceBackend<T> {
    /// A device at `target` (for messages), opened by `connect`, planning with `params`. Nothing
    /// is opened until the first request.
    pub fn new(target: &str, connect: Connect<T>, params: Params) -> Self {
        DeviceBackend {
            target: target.to_string(),
            connect,
            params,
            link: None,
            map: None,
            stale: false,
        }
    }

    /// The link, connected and told the parameters (and the map, after a reconnection).
    fn link(&mut self) -> Result<&mut Link<T>, BackendError> {
        if self.link.is_none() {
            let mut link = (self.connect)().map_err(|e| self.error(e))?;
            let info = link.hello().map_err(|e| self.error(e))?;
            link.set_params(&self.params).map_err(|e| self.error(e))?;
            log::info!(
                "connected to {} ({}, firmware {}, {} cells, sides up to {})",
                self.target,
                info.board,
                info.firmware_version,
                info.capacity.cells,
                info.capacity.max_side
            );
            self.link = Some((link, info));
            self.stale = self.map.is_some();
        }
        if self.stale {
            if let (Some((link, _)), Some(map)) = (self.link.as_mut(), self.map.as_ref()) {
                let r = link.set_map(map);
                if let Err(e) = r {
                    return Err(self.error(e));
                }
            }
            self.stale = false;
        }
        match self.link.as_mut() {
            Some((link, _)) => Ok(link),
            None => Err(BackendError::Unreachable(self.target.clone())),
        }
    }

    /// A link error as a backend error; a transport failure drops the link (reconnected next
    /// time).
    fn error(&mut self, e: LinkError) -> BackendError {
        let text = format!("{}: {e}", self.target);
        let transport = matches!(
            e,
            LinkError::Open { .. }
                | LinkError::Disconnected
                | LinkError::Io(_)
                | LinkError::Timeout { .. }
                | LinkError::Decode(_)
                | LinkError::Version { .. }
        );
        if transport {
            self.link = None;
        }
        match e {
            LinkError::Timeout { .. } => BackendError::Timeout(text),
            LinkError::Device { error, .. } => match error.code {
                ErrorCode::Busy => BackendError::Busy(text),
                ErrorCode::NoPath | ErrorCode::NoAntArrived | ErrorCode::PathTooLong => {
                    BackendError::NoPath(text)
                }
                _ => BackendError::Refused(text),
            },
            LinkError::Unexpected { .. } | LinkError::Encode { .. } | LinkError::BadPath(_) => {
                BackendError::Refused(text)
            }
            _ => BackendError::Unreachable(text),
        }
    }

    /// Run `f` on the link; a failure is a [`BackendError`].
    fn with<R>(
        &mut self,
        f: impl FnOnce(&mut Link<T>) -> Result<R, LinkError>,
    ) -> Result<R, BackendError> {
        let link = self.link()?;
        f(link).map_err(|e| self.error(e))
    }
}

impl<T: Transport> Backend for DeviceBackend<T> {
    fn describe(&self) -> String {
        match &self.link {
            Some((_, info)) => format!("{} at {}", info.board, self.target),
            None => format!("the device at {}", self.target),
        }
    }

    fn capacity(&mut self) -> Result<Option<Capacity>, BackendError> {
        self.link()?;
        Ok(self.link.as_ref().map(|(_, i)| i.capacity))
    }

    fn upload(&mut self, map: &Map) -> Result<(), BackendError> {
        self.map = Some(map.clone());
        self.stale = false;
        self.with(|l| l.set_map(map))
    }

    fn set_rect(&mut self, rect: (u16, u16, u16, u16), blocked: bool) -> Result<(), BackendError> {
        if let Some(m) = self.map.as_mut() {
            for p in rect_cells(rect) {
                let _ = m.set(p, blocked);
            }
        }
        let (x, y, w, h) = rect;
        self.with(|l| l.set_rect((x, y), (w, h), blocked))
    }

    fn set_cells(&mut self, cells: &[Point], blocked: bool) -> Result<(), BackendError> {
        if let Some(m) = self.map.as_mut() {
            for &p in cells {
                let _ = m.set(p, blocked);
            }
        }
        self.with(|l| l.set_cells(cells, blocked))
    }

    fn plan(&mut self, start: Point, goal: Point, warm: bool) -> Result<Planned, BackendError> {
        let p = self.with(|l| {
            if warm {
                l.plan_warm(start, goal, None)
            } else {
                l.plan(start, goal, None)
            }
        })?;
        let raw = p.raw(start).map_err(|e| self.error(e))?;
        Ok(Planned {
            raw,
            waypoints: p.waypoints.clone(),
            raw_length: p.raw_length,
            length: p.length,
            iterations: p.iterations,
            moves: p.moves,
            ticks: Some(p.ticks),
            origin: p.origin,
            fallback: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_host_core_plans_and_takes_changes() {
        let mut b = HostBackend::new(Params::default());
        assert_eq!(b.capacity(), Ok(None));
        let map = Map::from_fn(10, 10, |_, _| false);
        b.upload(&map).unwrap();
        let (s, g) = (Point::new(0, 5), Point::new(9, 5));
        let first = b.plan(s, g, true).unwrap();
        assert!(!first.origin.is_warm());
        b.set_rect((5, 0, 1, 9), true).unwrap();
        let second = b.plan(s, g, true).unwrap();
        assert!(second.origin.is_warm());
        assert!(second.raw.iter().all(|p| p.x != 5 || p.y == 9));
        b.set_rect((5, 0, 1, 10), true).unwrap();
        let no = b.plan(s, g, true);
        assert!(matches!(no, Err(BackendError::NoPath(_))));
        // Said once: "no path: the goal is ...", not "no path: no path: ...".
        let text = no.unwrap_err().to_string();
        assert_eq!(text.matches("no path").count(), 1, "{text}");
    }

    #[test]
    fn the_host_core_as_a_board_reports_its_capacity_and_refuses_more() {
        let mut b = HostBackend::on(Params::default(), ohaca::board::F411);
        let cap = b.capacity().unwrap().unwrap();
        assert_eq!(
            (cap.cells, cap.max_side, cap.max_steps),
            (
                ohaca::board::F411.cells as u32,
                ohaca::board::F411.max_side,
                ohaca::board::F411.max_steps as u32
            )
        );
        assert!(b.describe().contains("f411"));
        assert!(matches!(
            b.upload(&Map::from_fn(512, 513, |_, _| false)),
            Err(BackendError::Refused(_))
        ));
        b.upload(&Map::from_fn(10, 10, |_, _| false)).unwrap();
        assert!(b.plan(Point::new(0, 0), Point::new(9, 9), false).is_ok());
    }

    #[test]
    fn an_unreachable_device_is_an_error_not_a_panic() {
        let connect: Connect<std::net::TcpStream> =
            Box::new(|| Link::tcp("127.0.0.1:1", std::time::Duration::from_millis(200)));
        let mut b = DeviceBackend::new("127.0.0.1:1", connect, Params::default());
        let map = Map::from_fn(4, 4, |_, _| false);
        assert!(matches!(b.upload(&map), Err(BackendError::Unreachable(_))));
        assert!(matches!(
            b.plan(Point::new(0, 0), Point::new(3, 3), false),
            Err(BackendError::Unreachable(_))
        ));
    }
}
