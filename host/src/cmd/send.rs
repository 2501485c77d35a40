//! `ohaca send`: plan on the firmware. Connects to a device (`--tcp HOST:PORT`, e.g. QEMU's
//! UART, or `--serial DEVICE`), says Hello, sends the parameters and the map, plans, and prints
//! the result as `ohaca plan` does: the picture, the waypoints as CSV, or with `--json` the same
//! JSON keys plus `ticks` (device time, in the device's `tick_hz` units) and `device` (its board
//! name). `elapsed_us` is the round trip of the plan request as the host saw it.
//!
//! The map flags are `plan`'s (`--unknown`, `--inflate`, `--cell`, `--start-m`, `--goal-m`). A
//! map goes at full resolution whenever it fits the capacity the device reports in Hello (its
//! cells, and its longest side); only a larger one is resampled, to the smallest whole
//! number of cells per coarse cell that fits (a coarse cell is blocked if any cell it covers is;
//! [`ohaca_host::map::fit`]), unless `--cell` was given; a note on stderr says so, with the new
//! cell size for maps with a resolution, and start, goal and output are cells of the coarse grid.
//!
//! The device's board is known from the capacity in Hello (`ohaca::board::Board::with_capacity`):
//! when it plans the map in another layout than `ohaca plan` does by default (the STM32F411's
//! compact one, on maps of more than 68,256 cells), a note on stderr says so and names the
//! `ohaca plan --board` that gives the device's path (not for a map fitted to the device, which
//! has its own note).
//!
//! `--goals FILE` plans many requests over one connection, pipelined, and prints one JSON line
//! per request, in file order. Each line of the file is `SX,SY GX,GY` (start and goal) or
//! `GX,GY` (a goal from `--start`); `#` starts a comment, blank lines are skipped.
//!
//! Exit codes as `ohaca plan`: 0 path found (every path, with `--goals`); 1 no path (some
//! request, with `--goals`); 2 bad input (map, parameters, start/goal, goals file, a map larger
//! than the device holds), a device error, a timeout or a lost connection, with one `error:`
//! line on stderr.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use ohaca::board::Board;
use ohaca::protocol::{ErrorCode, ErrorReply};
use ohaca::{Error, Params, Point};
use ohaca_host::args::PointError;
use ohaca_host::board::differs_from_host;
use ohaca_host::input::{resolve_point, MapArgs};
use ohaca_host::link::{DeviceInfo, DevicePath, Link, LinkError, PlanJob, Transport, DEFAULT_BAUD};
use ohaca_host::map::{fit, fits, prepare, FitError, Fitted, MapError, MapFrame};
use ohaca_host::output::{format_us, micros, render, waypoints_csv, xy, LocatedReport, PlanReport};
use ohaca_host::{exit, parse_point, Map, ParamArgs};
use serde::Serialize;

use super::plan::Format;
use super::{bad_input, print};

/// Arguments of `ohaca send`.
#[derive(clap::Args, Debug)]
#[command(group(clap::ArgGroup::new("device").required(true).args(["tcp", "serial"])))]
// `--goals FILE` takes the place of `--goal`, and its lines may carry their own starts.
#[command(mut_arg("start", |a| a.required_unless_present("goals")))]
#[command(mut_arg("goal", |a| a.required_unless_present("goals").conflicts_with("goals")))]
#[command(mut_arg("goal_m", |a| a.conflicts_with("goals")))]
pub struct Args {
    /// Device on a TCP port, e.g. QEMU's UART (scripts/qemu-serve.sh): HOST:PORT
    #[arg(long, value_name = "HOST:PORT")]
    pub tcp: Option<String>,
    /// Device on a serial port, e.g. /dev/ttyUSB0 (8N1, no flow control)
    #[arg(long, value_name = "DEVICE")]
    pub serial: Option<String>,
    /// Serial line speed
    #[arg(long, value_name = "N", default_value_t = DEFAULT_BAUD)]
    pub baud: u32,
    /// Seconds to wait for each reply (and for the connection)
    #[arg(long, value_name = "SECONDS", default_value = "10", value_parser = parse_timeout)]
    pub timeout: Duration,
    #[command(flatten)]
    pub input: MapArgs,
    /// Plan every line of FILE (`SX,SY GX,GY`, or `GX,GY` from --start; `#` comments) over one
    /// connection; prints one JSON line per request, in order
    #[arg(long, value_name = "FILE")]
    pub goals: Option<PathBuf>,
    /// What to print: text (picture), json or csv [default: text; json lines with --goals]
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub format: Option<Format>,
    /// Print one JSON object instead of the picture (same as --format json)
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub params: ParamArgs,
}

/// A bad `--timeout`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
enum TimeoutError {
    /// Not a number.
    #[error("expected seconds, found `{0}`")]
    NotSeconds(String),
    /// Not in (0, 86400].
    #[error("timeout must be in (0, 86400] seconds, found {0}")]
    Range(String),
}

/// `TARGET: ` before a link error, or nothing.
fn target_prefix(target: &Option<String>) -> String {
    target
        .as_ref()
        .map(|t| format!("{t}: "))
        .unwrap_or_default()
}

/// `--timeout`: positive seconds, at most a day.
fn parse_timeout(s: &str) -> Result<Duration, TimeoutError> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| TimeoutError::NotSeconds(s.to_string()))?;
    if !(v > 0.0 && v <= 86_400.0) {
        return Err(TimeoutError::Range(s.to_string()));
    }
    Duration::try_from_secs_f64(v).map_err(|_| TimeoutError::Range(s.to_string()))
}

/// A bad line of a goals file.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
enum GoalLineError {
    /// A point is malformed.
    #[error(transparent)]
    Point(#[from] PointError),
    /// A goal alone, and no `--start`.
    #[error("a goal without a start: give `SX,SY GX,GY`, or --start")]
    NoStart,
    /// Not one or two points.
    #[error("expected `SX,SY GX,GY`, found `{0}`")]
    Shape(String),
}

/// Why `ohaca send` failed (printed as `error: ...`, exit code 2).
#[derive(Debug, thiserror::Error)]
enum SendError {
    /// `--json` with another `--format`.
    #[error("--json means --format json; it cannot be combined with --format {0}")]
    JsonAndFormat(&'static str),
    /// `--goals` with a format other than JSON.
    #[error("--goals prints one JSON line per request: use --format json")]
    GoalsNotJson,
    /// Neither a start and a goal nor `--goals`.
    #[error("give --start (or --start-m) and --goal (or --goal-m), or --goals")]
    NoEndpoints,
    /// Neither `--tcp` nor `--serial`.
    #[error("give --tcp HOST:PORT or --serial DEVICE")]
    NoDevice,
    /// No job.
    #[error("nothing to plan")]
    NothingToPlan,
    /// The map or a point in metres.
    #[error(transparent)]
    Map(#[from] MapError),
    /// The parameters are out of range (the core's words).
    #[error("{0}")]
    Params(Error),
    /// The goals file cannot be read.
    #[error("{}: cannot read the file: {error}", .path.display())]
    ReadGoals {
        /// The file.
        path: PathBuf,
        /// The system's error.
        error: std::io::Error,
    },
    /// A line of the goals file is bad.
    #[error("{}, line {line}: {error}", .path.display())]
    GoalLine {
        /// The file.
        path: PathBuf,
        /// The line (from 1).
        line: usize,
        /// What is wrong with it.
        error: GoalLineError,
    },
    /// The goals file has no pair.
    #[error("{}: no start/goal pairs", .0.display())]
    NoGoals(PathBuf),
    /// The map does not fit the device (with `--cell`, or not even fitted).
    #[error(
        "{}: map too large for the device: {width}x{height} = {cells} cells, but {board} holds \
         at most {capacity} cells (sides up to {max_side}); use a smaller map",
        .path.display()
    )]
    TooLarge {
        /// The map file.
        path: PathBuf,
        /// Its width in cells.
        width: u16,
        /// Its height in cells.
        height: u16,
        /// Its cells.
        cells: usize,
        /// The device's board.
        board: String,
        /// The device's most cells.
        capacity: u32,
        /// The device's longest side.
        max_side: u16,
    },
    /// A start or goal is off the map (checked before fitting the map).
    #[error("{name}: {what} {},{} is outside the map ({width}x{height})", .at.x, .at.y)]
    Outside {
        /// The map's name.
        name: String,
        /// `start` or `goal`.
        what: &'static str,
        /// The cell.
        at: Point,
        /// The map's width.
        width: u16,
        /// The map's height.
        height: u16,
    },
    /// A start or goal is on an obstacle (checked before fitting the map).
    #[error("{name}: {what} {},{} is on an obstacle", .at.x, .at.y)]
    Blocked {
        /// The map's name.
        name: String,
        /// `start` or `goal`.
        what: &'static str,
        /// The cell.
        at: Point,
    },
    /// The map cannot be fitted to the device.
    #[error("{name}: {error}")]
    Fit {
        /// The map's name.
        name: String,
        /// Why.
        error: FitError,
    },
    /// The link failed, or the device refused a request.
    #[error("{}{error}", target_prefix(.target))]
    Link {
        /// The device's address (`None` when the error names it: opening the link).
        target: Option<String>,
        /// What failed.
        error: LinkError,
    },
    /// The device's answer to the plan is an error of the user's input, or a bad path.
    #[error("{0}")]
    Answer(String),
}

/// What `send --json` prints: the `plan` report's keys (`waypoints_m` too, for maps with a
/// resolution), then `ticks` and `device`.
#[derive(Serialize)]
struct SendReport<'a> {
    #[serde(flatten)]
    report: LocatedReport<'a>,
    /// Device time of the plan (`tick_hz` units), null if no path.
    ticks: Option<u64>,
    /// The device's board name.
    device: &'a str,
}

impl SendReport<'_> {
    fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_else(|e| {
            format!(
                "{{\"found\":false,\"error\":{}}}",
                serde_json::Value::String(e.to_string())
            )
        })
    }
}

/// Run `ohaca send`; returns the exit code.
pub fn run(args: &Args) -> u8 {
    match Sender::prepare(args).and_then(|mut s| s.run(args)) {
        Ok(code) => code,
        Err(msg) => bad_input(msg),
    }
}

/// The connected state of one `send`.
struct Sender {
    /// `--tcp` or `--serial`, for messages.
    target: String,
    /// The map file as given, for messages.
    name: String,
    map: Map,
    /// Where the map's cells are in metres (ROS maps).
    metric: Option<MapFrame>,
    params: Params,
    jobs: Vec<PlanJob>,
    /// What to print.
    format: Format,
    /// The map as sent when it had to be cropped or resampled to fit the device; `map`,
    /// `metric` and the jobs' cells are then the fitted map's, and outputs go back to the
    /// original map's cells through it.
    fitted: Option<Fitted>,
    /// The jobs in the original map's cells (before fitting).
    original_jobs: Vec<PlanJob>,
}

/// One line of a goals file.
fn parse_goal_line(line: &str, start: Option<Point>) -> Result<Option<PlanJob>, GoalLineError> {
    let text = line.split('#').next().unwrap_or("");
    let words: Vec<&str> = text.split_whitespace().collect();
    let (s, g) = match words.as_slice() {
        [] => return Ok(None),
        [g] => (start.ok_or(GoalLineError::NoStart)?, parse_point(g)?),
        [s, g] => (parse_point(s)?, parse_point(g)?),
        _ => return Err(GoalLineError::Shape(text.trim().to_string())),
    };
    Ok(Some(PlanJob {
        start: s,
        goal: g,
        seed: None,
    }))
}

/// Every request of a goals file.
fn load_goals(path: &Path, start: Option<Point>) -> Result<Vec<PlanJob>, SendError> {
    let text = std::fs::read_to_string(path).map_err(|error| SendError::ReadGoals {
        path: path.to_path_buf(),
        error,
    })?;
    let mut jobs = Vec::new();
    for (i, line) in text.lines().enumerate() {
        match parse_goal_line(line, start) {
            Ok(Some(j)) => jobs.push(j),
            Ok(None) => {}
            Err(error) => {
                return Err(SendError::GoalLine {
                    path: path.to_path_buf(),
                    line: i + 1,
                    error,
                })
            }
        }
    }
    if jobs.is_empty() {
        return Err(SendError::NoGoals(path.to_path_buf()));
    }
    Ok(jobs)
}

/// A map the device cannot hold.
fn too_large(map_path: &Path, map: &Map, info: &DeviceInfo) -> SendError {
    let c = &info.capacity;
    SendError::TooLarge {
        path: map_path.to_path_buf(),
        width: map.width,
        height: map.height,
        cells: map.cells(),
        board: info.board.clone(),
        capacity: c.cells,
        max_side: c.max_side,
    }
}

/// A note when the device plans `map` in another layout than `ohaca plan` does by default (the
/// STM32F411's compact layout on maps of more than 68,256 cells): the device's board is known
/// from the capacity in its Hello ([`Board::with_capacity`]).
fn layout_note(info: &DeviceInfo, map: &Map) -> Option<String> {
    let c = &info.capacity;
    let board = Board::with_capacity(
        usize::try_from(c.cells).ok()?,
        usize::try_from(c.max_steps).ok()?,
    )?;
    let layout = differs_from_host(&board, map.cells())?;
    Some(format!(
        "{} plans this {}x{} map in its compact layout (paths of up to {} steps, no pruning, \
         coarser pheromone), not in the host's default one: `ohaca plan --board {}` gives the \
         device's path",
        info.board, map.width, map.height, layout.steps, board.name
    ))
}

impl Sender {
    /// Everything that can be checked before connecting.
    fn prepare(args: &Args) -> Result<Sender, SendError> {
        let format = match (args.json, args.format, args.goals.is_some()) {
            (true, None | Some(Format::Json), _) => Format::Json,
            (true, Some(f), _) => {
                return Err(SendError::JsonAndFormat(if f == Format::Csv {
                    "csv"
                } else {
                    "text"
                }))
            }
            (false, None, true) | (false, Some(Format::Json), true) => Format::Json,
            (false, Some(_), true) => return Err(SendError::GoalsNotJson),
            (false, f, false) => f.unwrap_or(Format::Text),
        };
        let a = &args.input;
        let name = a.map.display().to_string();
        let (map, metric) = prepare(&a.map, a.unknown, a.inflate, a.cell)?;
        let params = args.params.params();
        params.validate().map_err(SendError::Params)?;
        let start = match (a.start, a.start_m) {
            (None, None) => None,
            (s, m) => Some(resolve_point(&name, metric, "start", s, m)?),
        };
        let jobs = match (&args.goals, start) {
            (Some(file), start) => load_goals(file, start)?,
            (None, Some(start)) => vec![PlanJob {
                start,
                goal: resolve_point(&name, metric, "goal", a.goal, a.goal_m)?,
                seed: None,
            }],
            (None, None) => return Err(SendError::NoEndpoints),
        };
        let target = args.tcp.as_deref().or(args.serial.as_deref()).unwrap_or("");
        Ok(Sender {
            target: target.to_string(),
            name,
            map,
            metric,
            params,
            jobs,
            format,
            fitted: None,
            original_jobs: Vec::new(),
        })
    }

    /// Fit the map to the device if it is too large and `--cell` was not given: crop it to its
    /// free area, then resample it only if that is not enough, keeping every start and goal free
    /// ([`ohaca_host::map::fit`]); the jobs' cells follow, and outputs go back to the original
    /// cells. With `--cell`, a map that does not fit is an error. A map that fits (cells and
    /// longest side) goes as it is.
    fn fit(&mut self, args: &Args, info: &DeviceInfo) -> Result<(), SendError> {
        let c = &info.capacity;
        if fits(&self.map, c) {
            return Ok(());
        }
        if args.input.cell.is_some() {
            return Err(too_large(&args.input.map, &self.map, info));
        }
        // A start or goal off the map or on an obstacle is the user's, at full resolution.
        for job in &self.jobs {
            for (what, p) in [("start", job.start), ("goal", job.goal)] {
                if p.x >= self.map.width || p.y >= self.map.height {
                    return Err(SendError::Outside {
                        name: self.name.clone(),
                        what,
                        at: p,
                        width: self.map.width,
                        height: self.map.height,
                    });
                }
                if self.map.is_blocked(p) {
                    return Err(SendError::Blocked {
                        name: self.name.clone(),
                        what,
                        at: p,
                    });
                }
            }
        }
        let endpoints: Vec<Point> = self.jobs.iter().flat_map(|j| [j.start, j.goal]).collect();
        let fitted = fit(&self.map, self.metric, c, &endpoints)
            .map_err(|error| SendError::Fit {
                name: self.name.clone(),
                error,
            })?
            .ok_or_else(|| too_large(&args.input.map, &self.map, info))?;
        eprintln!("note: {}", fitted.note(&self.name, &info.board, c));
        self.original_jobs = self.jobs.clone();
        for job in &mut self.jobs {
            job.start = fitted.cell(job.start);
            job.goal = fitted.cell(job.goal);
        }
        self.map = fitted.map.clone();
        self.metric = fitted.metric;
        self.fitted = Some(fitted);
        Ok(())
    }

    /// A report of job `i` in the original map's cells, when the map was fitted: the raw path
    /// and the waypoints from the start and to the goal as given, through the centres of the
    /// fitted cells between them.
    fn in_original(&self, report: &PlanReport, i: usize) -> PlanReport {
        let mut r = report.clone();
        if let Some(f) = &self.fitted {
            let job = self.original_jobs.get(i);
            let back = |v: &mut Vec<[u16; 2]>| {
                for c in v.iter_mut() {
                    let p = f.original(Point::new(c[0], c[1]));
                    *c = [p.x, p.y];
                }
                if let (Some(j), Some(first)) = (job, v.first_mut()) {
                    *first = [j.start.x, j.start.y];
                }
                if let (Some(j), Some(last)) = (job, v.last_mut()) {
                    *last = [j.goal.x, j.goal.y];
                }
            };
            back(&mut r.raw);
            back(&mut r.waypoints);
        }
        r
    }

    /// The waypoints in metres (rounded to a micrometre), for maps with a resolution.
    fn metres(&self, waypoints: &[[u16; 2]]) -> Option<Vec<[f64; 2]>> {
        self.metric.map(|f| f.points_m(waypoints))
    }

    /// One `send --json` line: the report with `waypoints_m` (maps with a resolution), `ticks`
    /// and `device`.
    fn json_line(
        &self,
        report: &PlanReport,
        i: usize,
        ticks: Option<u64>,
        info: &DeviceInfo,
    ) -> String {
        let metres = self.metres(&report.waypoints);
        let original = self.in_original(report, i);
        let mut s = SendReport {
            report: LocatedReport {
                report: &original,
                waypoints_m: metres.as_deref(),
            },
            ticks,
            device: &info.board,
        }
        .to_json();
        s.push('\n');
        s
    }

    /// `error: <target>: <what>`.
    fn fail(&self, error: LinkError) -> SendError {
        let target = match error {
            LinkError::Open { .. } => None,
            _ => Some(self.target.clone()),
        };
        SendError::Link { target, error }
    }

    fn run(&mut self, args: &Args) -> Result<u8, SendError> {
        let fail = |e: LinkError| self.fail(e);
        match (&args.tcp, &args.serial) {
            (Some(addr), _) => {
                let link = Link::tcp(addr, args.timeout).map_err(fail)?;
                self.talk(args, link)
            }
            (None, Some(dev)) => {
                let link = Link::serial(dev, args.baud, args.timeout).map_err(fail)?;
                self.talk(args, link)
            }
            (None, None) => Err(SendError::NoDevice),
        }
    }

    fn talk<T: Transport>(&mut self, args: &Args, mut link: Link<T>) -> Result<u8, SendError> {
        let info = link.hello().map_err(|e| self.fail(e))?;
        self.fit(args, &info)?;
        // A fitted map has its note already, and `plan --board` of the original map cannot
        // reproduce a path on the fitted one.
        if let (None, Some(note)) = (&self.fitted, layout_note(&info, &self.map)) {
            eprintln!("note: {note}");
        }
        let fail = |e: LinkError| self.fail(e);
        link.set_params(&self.params).map_err(fail)?;
        // A progress bar on a terminal (never under --json or when stderr is a file or a pipe).
        let bar = self.format != Format::Json && std::io::stderr().is_terminal();
        let started = Instant::now();
        let uploaded = link.set_map_with_progress(&self.map, |done, all| {
            if bar {
                eprint!("{}", progress_bar("map", done, all, started.elapsed()));
            }
        });
        if bar {
            eprint!("\r\x1b[K");
        }
        uploaded.map_err(|e| match e {
            LinkError::Device { error, .. } if error.code == ErrorCode::MapTooLarge => {
                too_large(&args.input.map, &self.map, &info)
            }
            e => fail(e),
        })?;
        let code = if args.goals.is_some() {
            self.stream(&mut link, &info).map_err(fail)?
        } else {
            self.single(args, &mut link, &info)?
        };
        let strays = link.take_strays();
        if let Some(first) = strays.first() {
            eprintln!(
                "warning: skipped {} unexpected frame(s) from the device (first: {first})",
                link.stray_count()
            );
        }
        Ok(code)
    }

    /// One plan: picture or JSON.
    fn single<T: Transport>(
        &self,
        args: &Args,
        link: &mut Link<T>,
        info: &DeviceInfo,
    ) -> Result<u8, SendError> {
        let Some(job) = self.jobs.first() else {
            return Err(SendError::NothingToPlan);
        };
        let t0 = Instant::now();
        let result = match link.plan(job.start, job.goal, job.seed) {
            Ok(p) => Ok(p),
            Err(LinkError::Device { error, .. }) => Err(error),
            Err(e) => return Err(self.fail(e)),
        };
        let outcome = self.report(job, result, t0.elapsed());
        let (report, ticks) = match outcome {
            Outcome::Report(r, t) => (*r, t),
            Outcome::BadInput(msg) => return Err(SendError::Answer(msg)),
        };
        let code = if report.found {
            exit::FOUND
        } else {
            exit::NO_PATH
        };
        if self.format == Format::Csv {
            let metres = self.metres(&report.waypoints);
            let original = self.in_original(&report, 0);
            print(&waypoints_csv(&original.waypoints, metres.as_deref()));
        } else if self.format == Format::Json {
            print(&self.json_line(&report, 0, ticks, info));
        } else {
            let p = &report.params;
            let mut s = format!(
                "{}, ({},{}) -> ({},{}), {} seed {}, planned on {} (firmware {})\n",
                args.input.map.display(),
                job.start.x,
                job.start.y,
                job.goal.x,
                job.goal.y,
                p.algorithm,
                p.seed,
                info.board,
                info.firmware_version
            );
            s.push_str(&render(&self.map, job.start, job.goal, &report));
            if let (Some(_), true) = (&self.fitted, report.found) {
                let o = self.in_original(&report, 0);
                let pts: Vec<String> = o
                    .waypoints
                    .iter()
                    .map(|[x, y]| format!("({x},{y})"))
                    .collect();
                s.push_str("waypoints in the original map's cells: ");
                s.push_str(&pts.join(" "));
                s.push('\n');
            }
            if let (Some(m), true) = (self.metres(&report.waypoints), report.found) {
                let pts: Vec<String> = m.iter().map(|[x, y]| format!("({x}, {y})")).collect();
                s.push_str("waypoints in metres (map frame): ");
                s.push_str(&pts.join(" "));
                s.push('\n');
            }
            if let Some(t) = ticks {
                let hz = u64::from(info.capacity.tick_hz.max(1));
                let us =
                    u64::try_from(u128::from(t) * 1_000_000 / u128::from(hz)).unwrap_or(u64::MAX);
                // "planned in" above is the round trip the host saw (the link included).
                s.push_str(&format!(
                    "of which the device planned {} ({t} ticks at {hz} Hz)\n",
                    format_us(us),
                ));
            }
            print(&s);
        }
        Ok(code)
    }

    /// Many plans, pipelined; one JSON line each, in order.
    fn stream<T: Transport>(&self, link: &mut Link<T>, info: &DeviceInfo) -> Result<u8, LinkError> {
        let mut code = exit::FOUND;
        link.plan_each(&self.jobs, |i, o| {
            let Some(job) = self.jobs.get(i) else { return };
            let (report, ticks) = match self.report(job, o.result, o.round_trip) {
                Outcome::Report(r, t) => {
                    if !r.found {
                        code = code.max(exit::NO_PATH);
                    }
                    (*r, t)
                }
                Outcome::BadInput(msg) => {
                    code = exit::BAD_INPUT;
                    (
                        PlanReport::not_found(&self.params, msg, None, o.round_trip),
                        None,
                    )
                }
            };
            print(&self.json_line(&report, i, ticks, info));
        })?;
        Ok(code)
    }

    /// The `plan`-style report of one device answer.
    fn report(
        &self,
        job: &PlanJob,
        result: Result<DevicePath, ErrorReply>,
        round_trip: Duration,
    ) -> Outcome {
        let params = Params {
            seed: job.seed.unwrap_or(self.params.seed),
            ..self.params
        };
        let path = match result {
            Ok(p) => p,
            Err(e) => {
                return match Error::try_from(e).ok() {
                    Some(err @ Error::NoPath) => Outcome::found(
                        PlanReport::not_found(&params, err, Some(0), round_trip),
                        None,
                    ),
                    Some(err @ (Error::NoAntArrived | Error::PathTooLong { .. })) => {
                        Outcome::found(PlanReport::not_found(&params, err, None, round_trip), None)
                    }
                    Some(err @ (Error::OutOfBounds(_) | Error::Blocked(_))) => {
                        Outcome::BadInput(format!(
                            "{}: {err} (start {},{}, goal {},{}, map {}x{})",
                            self.name,
                            job.start.x,
                            job.start.y,
                            job.goal.x,
                            job.goal.y,
                            self.map.width,
                            self.map.height
                        ))
                    }
                    Some(err) => Outcome::BadInput(format!("device: {err}")),
                    None => Outcome::BadInput(format!(
                        "device refused the plan: {e} (error code {})",
                        e.code.code()
                    )),
                };
            }
        };
        let raw = match path.raw(job.start) {
            Ok(r) => r,
            Err(e) => return Outcome::BadInput(e.to_string()),
        };
        if raw.last() != Some(&job.goal) || path.waypoints.last() != Some(&job.goal) {
            return Outcome::BadInput(format!(
                "bad path from the device: it does not end at the goal {},{}",
                job.goal.x, job.goal.y
            ));
        }
        let report = PlanReport {
            found: true,
            raw: raw.into_iter().map(xy).collect(),
            waypoints: path.waypoints.iter().copied().map(xy).collect(),
            raw_length: Some(path.raw_length),
            length: Some(path.length),
            turns: Some(path.turns),
            iterations: Some(path.iterations),
            best_iteration: Some(path.best_iteration),
            moves: Some(path.moves),
            elapsed_us: micros(round_trip),
            params,
            error: None,
            shortfalls: None,
        };
        Outcome::found(report, Some(path.ticks))
    }
}

/// A device answer as a report (with its ticks), or a bad-input message.
enum Outcome {
    Report(Box<PlanReport>, Option<u64>),
    BadInput(String),
}

impl Outcome {
    /// A report (found, or a normal "no path").
    fn found(report: PlanReport, ticks: Option<u64>) -> Self {
        Outcome::Report(Box::new(report), ticks)
    }
}

/// One frame of a terminal progress bar (carriage return first, no newline): `map [####    ]
/// 45 % 12.3 of 27.1 KiB, 1.2 s`.
fn progress_bar(what: &str, done: usize, all: usize, elapsed: Duration) -> String {
    const WIDTH: usize = 30;
    let all = all.max(1);
    let filled = (done.min(all) * WIDTH) / all;
    format!(
        "\r{what} [{}{}] {:>3} % {:.1} of {:.1} KiB, {:.1} s",
        "#".repeat(filled),
        " ".repeat(WIDTH - filled),
        done.min(all) * 100 / all,
        done as f64 / 1024.0,
        all as f64 / 1024.0,
        elapsed.as_secs_f64()
    )
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn the_progress_bar_fills_with_the_bytes() {
        let t = Duration::from_millis(1500);
        assert_eq!(
            progress_bar("map", 0, 2048, t),
            "\rmap [                              ]   0 % 0.0 of 2.0 KiB, 1.5 s"
        );
        assert_eq!(
            progress_bar("map", 1024, 2048, t),
            "\rmap [###############               ]  50 % 1.0 of 2.0 KiB, 1.5 s"
        );
        assert!(
            progress_bar("map", 2048, 2048, t).contains("[##############################] 100 %")
        );
        // Nothing to send divides by nothing.
        assert!(progress_bar("map", 0, 0, t).contains("  0 %"));
    }

    #[test]
    fn goal_lines() {
        let s = Some(Point::new(1, 2));
        assert_eq!(parse_goal_line("  # nothing", None), Ok(None));
        assert_eq!(parse_goal_line("", None), Ok(None));
        let j = parse_goal_line("3,4 5,6 # pair", None).unwrap().unwrap();
        assert_eq!((j.start, j.goal), (Point::new(3, 4), Point::new(5, 6)));
        let j = parse_goal_line("7,8", s).unwrap().unwrap();
        assert_eq!((j.start, j.goal), (Point::new(1, 2), Point::new(7, 8)));
        assert!(parse_goal_line("7,8", None).is_err());
        assert!(parse_goal_line("1,2 3,4 5,6", None).is_err());
        assert!(parse_goal_line("1;2 3,4", None).is_err());
    }

    #[test]
    fn timeouts() {
        assert_eq!(parse_timeout("2.5"), Ok(Duration::from_millis(2500)));
        for bad in ["0", "-1", "nan", "inf", "x", "1e9"] {
            assert!(parse_timeout(bad).is_err(), "{bad}");
        }
    }
}
