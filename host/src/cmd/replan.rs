//! `ohaca replan`: drive a robot through a replanning scenario ([`ohaca_host::replan`]) on the
//! host core or on a device (`--tcp` / `--serial`), warm (`PlanWarm`, the default), cold
//! (`--cold`) or both side by side (`--compare`), print a table of every plan and draw the drive
//! (`--png` strip of panels, `--gif` animation). `--dstar` replays every drive into D* Lite
//! ([`ohaca_host::dstar::replay`], one persistent search a drive) and adds its cost and the exact
//! A*'s from scratch, plan by plan.
//!
//! Exit codes: 0 every plan found a valid path; 1 a plan failed (no path, a device error or an
//! invalid path); 2 bad input.

use std::path::PathBuf;
use std::time::{Duration, TryFromFloatSecsError};

use ohaca::Params;
use ohaca::Point;
use ohaca_host::board::BoardArg;
use ohaca_host::dstar::{self, AstarCost, DStarError, Stats};
use ohaca_host::input::MapArgs;
use ohaca_host::link::{Link, LinkError, Transport, DEFAULT_BAUD};
use ohaca_host::replan::{
    drive, DevicePlanner, Drive, HostPlanner, Planner, ReplanError, Scenario,
};
use ohaca_host::stream::{stream, summary as summary_of, Stream, Summary};
use ohaca_host::{exit, strip, ParamArgs};
use serde::Serialize;

use super::{bad_input, print};

/// Arguments of `ohaca replan`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub input: MapArgs,
    /// The changes: a JSON file (see `docs/HOST.md`, `ohaca replan`)
    #[arg(long, value_name = "FILE", required_unless_present = "stream")]
    pub events: Option<PathBuf>,
    /// Instead of `--events`: a costmap stream of N small random updates, a replan after each
    /// (`ohaca_host::stream`; one new obstacle in ten on or next to the path)
    #[arg(long, value_name = "N", conflicts_with = "events")]
    pub stream: Option<usize>,
    /// Stream: updates a second
    #[arg(long, value_name = "HZ", default_value_t = 5.0)]
    pub hz: f64,
    /// Stream: the robot's speed, cells a second
    #[arg(long, value_name = "CELLS", default_value_t = 10.0)]
    pub speed: f64,
    /// Stream: share of new obstacles on or next to the path
    #[arg(long, value_name = "SHARE", default_value_t = 0.1)]
    pub near: f64,
    /// Stream: the board's clock for the share of its time spent planning (device instructions
    /// over the stream's duration)
    #[arg(long, value_name = "MHZ", default_value_t = 100.0)]
    pub clock_mhz: f64,
    /// Plan on a device over TCP, e.g. QEMU's UART (default: the host core)
    #[arg(long, value_name = "HOST:PORT", conflicts_with = "serial")]
    pub tcp: Option<String>,
    /// Plan on a device on a serial port
    #[arg(long, value_name = "DEVICE")]
    pub serial: Option<String>,
    /// Plan on the host core exactly as this board's firmware does: f411 (also the default QEMU
    /// firmware) or h743 (also its QEMU twin) [default: as the f411, with heap storage on maps
    /// larger than its arena]
    #[arg(long, value_enum, value_name = "BOARD", conflicts_with_all = ["tcp", "serial"])]
    pub board: Option<BoardArg>,
    /// Serial baud rate
    #[arg(long, value_name = "N", default_value_t = DEFAULT_BAUD)]
    pub baud: u32,
    /// Seconds to wait for each reply
    #[arg(long, value_name = "SECONDS", default_value_t = 120.0)]
    pub timeout: f64,
    /// Replan cold (a fresh colony each time) instead of warm
    #[arg(long, conflicts_with = "compare")]
    pub cold: bool,
    /// Drive the scenario twice, cold then warm, and compare the replans
    #[arg(long)]
    pub compare: bool,
    /// Draw the (warm) drive as a strip of PNG panels, one per plan
    #[arg(long, value_name = "FILE")]
    pub png: Option<PathBuf>,
    /// Draw the (warm) drive as an animated GIF
    #[arg(long, value_name = "FILE")]
    pub gif: Option<PathBuf>,
    /// Also replay each drive into D* Lite (one incremental search across the drive's plans) and
    /// print its expansions and memory, and the exact A*'s from scratch, for every plan
    #[arg(long)]
    pub dstar: bool,
    /// Print one JSON object instead of the table
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub params: ParamArgs,
}

/// One plan, as printed.
#[derive(Serialize)]
struct Row {
    mode: &'static str,
    plan: usize,
    robot: [u16; 2],
    changed: usize,
    changed_cells: Vec<[u16; 2]>,
    blocked: bool,
    warm: bool,
    origin: &'static str,
    /// Why a warm plan was not answered without a run (the host core's reason).
    #[serde(skip_serializing_if = "Option::is_none")]
    fallback: Option<String>,
    iterations: u16,
    moves: u64,
    ticks: Option<u64>,
    raw_length: f32,
    length: f32,
    optimum: Option<f64>,
    /// `--dstar`: D* Lite's cost for this plan's problem, and the exact A*'s.
    #[serde(skip_serializing_if = "Option::is_none")]
    dstar: Option<DstarCols>,
}

/// `--dstar`'s columns of a plan.
#[derive(Serialize)]
struct DstarCols {
    /// D* Lite, persisted across the drive (the work since the previous plan).
    #[serde(flatten)]
    stats: Stats,
    /// The exact A* (`ohaca::astar::search`) from scratch on the same problem.
    astar: AstarCost,
}

fn rows(mode: &'static str, d: &Drive) -> Vec<Row> {
    d.steps
        .iter()
        .enumerate()
        .map(|(i, s)| Row {
            mode,
            plan: i,
            robot: [s.robot.x, s.robot.y],
            changed: s.changed.len(),
            changed_cells: s.changed.iter().map(|p| [p.x, p.y]).collect(),
            blocked: s.blocked,
            warm: s.plan.origin.is_warm(),
            origin: s.plan.origin.name(),
            fallback: s.plan.fallback.map(|f| f.to_string()),
            iterations: s.plan.iterations,
            moves: s.plan.moves,
            ticks: s.plan.ticks,
            raw_length: s.plan.raw_length,
            length: s.plan.length,
            optimum: s.optimum,
            dstar: None,
        })
        .collect()
}

/// Replay `d` into D* Lite and attach its columns to `rows` (the drive's rows, in order).
fn add_dstar(rows: &mut [Row], d: &Drive, goal: Point) -> Result<(), CmdError> {
    let replayed = dstar::replay(d, goal)?;
    for (row, r) in rows.iter_mut().zip(replayed) {
        row.dstar = Some(DstarCols {
            stats: r.dstar,
            astar: r.astar,
        });
    }
    Ok(())
}

/// A device over `link`, told the parameters.
fn device<T: Transport + 'static>(
    mut link: Link<T>,
    params: &Params,
) -> Result<Box<dyn Planner>, CmdError> {
    link.hello()?;
    link.set_params(params)?;
    Ok(Box::new(DevicePlanner { link }))
}

fn planner(args: &Args) -> Result<Box<dyn Planner>, CmdError> {
    let params = args.params.params();
    let timeout = Duration::try_from_secs_f64(args.timeout)?;
    if let Some(addr) = &args.tcp {
        return device(Link::tcp(addr, timeout)?, &params);
    }
    if let Some(port) = &args.serial {
        let link = Link::serial(port, args.baud, timeout)?;
        return device(link, &params);
    }
    Ok(match args.board {
        None => Box::new(HostPlanner::new(params)),
        Some(b) => Box::new(HostPlanner::on(params, b.board())),
    })
}

/// Bytes in KiB, one decimal.
fn kib(bytes: usize) -> String {
    format!("{:.1} K", bytes as f64 / 1024.0)
}

fn table(rows: &[Row]) -> String {
    let mut out = String::from(
        "mode  plan  robot       changed      origin  iterations  moves      instructions  raw     smoothed  optimum  raw/opt",
    );
    if rows.iter().any(|r| r.dstar.is_some()) {
        out += "  D* exp     D* mem     A* exp     A* mem";
    }
    out += "\n";
    for r in rows {
        let changed = match (r.plan, r.changed) {
            (0, 0) => "-".to_string(),
            (_, n) => format!("{n} {}", if r.blocked { "blocked" } else { "cleared" }),
        };
        let instr = r
            .ticks
            .map_or("-".to_string(), |t| format!("{:.2} M", t as f64 / 1000.0));
        let opt = r.optimum.map_or("-".into(), |o| format!("{o:.2}"));
        let ratio = r.optimum.map_or("-".into(), |o| {
            format!("{:.4}", f64::from(r.raw_length) / o)
        });
        let dstar = r.dstar.as_ref().map_or(String::new(), |d| {
            format!(
                "  {:<10} {:<10} {:<10} {}",
                d.stats.expanded,
                kib(d.stats.memory_bytes),
                d.astar.expanded,
                kib(d.astar.memory_bytes)
            )
        });
        out += &format!(
            "{:<5} {:<5} {:<11} {:<12} {:<7} {:<11} {:<10} {:<13} {:<7.2} {:<9.2} {:<8} {:<7}{dstar}\n",
            r.mode,
            r.plan,
            format!("({},{})", r.robot[0], r.robot[1]),
            changed,
            r.origin,
            r.iterations,
            r.moves,
            instr,
            r.raw_length,
            r.length,
            opt,
            ratio
        );
        if let Some(why) = &r.fallback {
            out += &format!("{:<12}not reused: {why}\n", "");
        }
    }
    out
}

/// Why `ohaca replan` cannot start or finish (printed as `error: ...`).
#[derive(Debug, thiserror::Error)]
enum CmdError {
    /// The events file cannot be read.
    #[error(transparent)]
    Read(#[from] std::io::Error),
    /// The events file is not a scenario.
    #[error(transparent)]
    Scenario(#[from] ReplanError),
    /// `--timeout` is not a duration.
    #[error("--timeout: {0}")]
    Timeout(#[from] TryFromFloatSecsError),
    /// The device cannot be reached or refused `Hello` or the parameters.
    #[error(transparent)]
    Link(#[from] LinkError),
    /// D* Lite's replay failed.
    #[error("D* Lite: {0}")]
    DStar(#[from] DStarError),
}

/// Run `ohaca replan`; returns the exit code.
pub fn run(args: &Args) -> u8 {
    let sc = match args.input.load() {
        Ok(s) => s,
        Err(e) => return bad_input(e),
    };
    let events = match &args.events {
        Some(path) => match std::fs::read_to_string(path)
            .map_err(CmdError::from)
            .and_then(|t| Ok(Scenario::parse(&t)?))
        {
            Ok(e) => Some(e),
            Err(e) => return bad_input(format_args!("{}: {e}", path.display())),
        },
        None => None,
    };
    let costmap = Stream {
        updates: args.stream.unwrap_or(0),
        hz: args.hz,
        speed: args.speed,
        near: args.near,
        seed: args.params.params().seed,
    };
    let mut p = match planner(args) {
        Ok(p) => p,
        Err(e) => return bad_input(e),
    };
    let ends = (sc.start, sc.goal);
    let modes: &[(&'static str, bool)] = if args.compare {
        &[("cold", false), ("warm", true)]
    } else if args.cold {
        &[("cold", false)]
    } else {
        &[("warm", true)]
    };
    let mut all = Vec::new();
    let mut last = None;
    let mut streams = Vec::new();
    for &(name, warm) in modes {
        let d = match &events {
            Some(ev) => drive(ev, &sc.map, ends, p.as_mut(), warm),
            None => stream(&costmap, &sc.map, ends, p.as_mut(), warm),
        };
        match d {
            Ok(d) => {
                let mut r = rows(name, &d);
                if args.dstar {
                    if let Err(e) = add_dstar(&mut r, &d, sc.goal) {
                        eprintln!("error: {name} drive: {e}");
                        return exit::NO_PATH;
                    }
                }
                all.extend(r);
                if events.is_none() {
                    streams.push((name, summary_of(&d, costmap.hz, args.clock_mhz * 1e6)));
                }
                last = Some(d);
            }
            Err(e) => {
                eprintln!("error: {name} drive: {e}");
                return exit::NO_PATH;
            }
        }
    }
    if args.json {
        print(&format!(
            "{}\n",
            serde_json::to_string(&all).unwrap_or_else(|e| format!("{{\"error\":\"{e}\"}}"))
        ));
    } else {
        print(&table(&all));
        if args.compare && events.is_some() {
            print(&summary(&all));
        }
        for (name, s) in &streams {
            print(&stream_line(name, s, args.clock_mhz));
        }
        if args.dstar {
            print(&dstar_summary(&all));
        }
    }
    if let Some(d) = &last {
        for (path, save) in [
            (
                &args.png,
                strip::save_strip as fn(&Drive, Point, &std::path::Path) -> _,
            ),
            (&args.gif, strip::save_gif),
        ] {
            if let Some(path) = path {
                if let Err(e) = save(d, sc.goal, path) {
                    return bad_input(e);
                }
            }
        }
    }
    exit::FOUND
}

/// One line on a stream: answers by kind, cost, and the share of the board's time planning.
fn stream_line(name: &str, s: &Summary, clock_mhz: f64) -> String {
    let cost = match (s.instructions, s.busy) {
        (Some(i), Some(b)) => format!(
            "{:.1} M instructions, {:.1} % of a {clock_mhz} MHz core's time",
            i as f64 / 1e6,
            100.0 * b
        ),
        _ => format!("{} ant moves", s.moves),
    };
    format!(
        "stream {name}: {} replans in {:.1} s: {} reused, {} repaired, {} warm, {} cold; {cost}\n",
        s.replans, s.seconds, s.reused, s.repaired, s.warm, s.cold
    )
}

/// Warm against cold, replan by replan: cost (instructions on a device, ant moves on the host) and
/// raw length.
fn summary(rows: &[Row]) -> String {
    let mut out = String::new();
    let cold: Vec<&Row> = rows
        .iter()
        .filter(|r| r.mode == "cold" && r.plan > 0)
        .collect();
    let warm: Vec<&Row> = rows
        .iter()
        .filter(|r| r.mode == "warm" && r.plan > 0)
        .collect();
    for (c, w) in cold.iter().zip(&warm) {
        let cost = match (c.ticks, w.ticks) {
            (Some(ct), Some(wt)) if ct > 0 => {
                format!("instructions {:.1} %", 100.0 * wt as f64 / ct as f64)
            }
            _ if c.moves > 0 => {
                format!("ant moves {:.1} %", 100.0 * w.moves as f64 / c.moves as f64)
            }
            _ => "-".into(),
        };
        out += &format!(
            "replan {}: warm/cold {cost}, iterations {}/{}, raw length {:+.2} %\n",
            w.plan,
            w.iterations,
            c.iterations,
            100.0 * (f64::from(w.raw_length) / f64::from(c.raw_length) - 1.0)
        );
    }
    out
}

/// `--dstar`, drive by drive: D* Lite's initial search and its replans against the exact A* from
/// scratch on the same problems (expansions), and the memory each keeps at its most.
fn dstar_summary(rows: &[Row]) -> String {
    let mut out = String::new();
    let mut modes: Vec<&str> = rows.iter().map(|r| r.mode).collect();
    modes.dedup();
    for mode in modes {
        let d: Vec<&DstarCols> = rows
            .iter()
            .filter(|r| r.mode == mode)
            .filter_map(|r| r.dstar.as_ref())
            .collect();
        let Some(first) = d.first() else { continue };
        let replans = d.get(1..).unwrap_or_default();
        let list = |f: &dyn Fn(&DstarCols) -> String| {
            replans.iter().map(|c| f(c)).collect::<Vec<_>>().join(", ")
        };
        let mem = d.iter().map(|c| c.stats.memory_bytes).max().unwrap_or(0);
        let amem = d.iter().map(|c| c.astar.memory_bytes).max().unwrap_or(0);
        out += &format!(
            "D* Lite ({mode} drive): initial {} expansions (A* {}); replans {} (A* from scratch {}); memory {} (A* {})\n",
            first.stats.expanded,
            first.astar.expanded,
            if replans.is_empty() { "-".into() } else { list(&|c| c.stats.expanded.to_string()) },
            if replans.is_empty() { "-".into() } else { list(&|c| c.astar.expanded.to_string()) },
            kib(mem),
            kib(amem)
        );
    }
    out
}
