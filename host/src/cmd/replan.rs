//! `ohaca replan`: drive a robot through a replanning scenario ([`ohaca_host::replan`]) on the
//! host core or on a device (`--tcp` / `--serial`), warm (`PlanWarm`, the default), cold
//! (`--cold`) or both side by side (`--compare`), print a table of every plan and draw the drive
//! (`--png` strip of panels, `--gif` animation).
//!
//! Exit codes: 0 every plan found a valid path; 1 a plan failed (no path, a device error or an
//! invalid path); 2 bad input.

use std::path::PathBuf;
use std::time::Duration;

use ohaca::Params;
use ohaca::Point;
use ohaca_host::board::BoardArg;
use ohaca_host::input::MapArgs;
use ohaca_host::link::{Link, Transport, DEFAULT_BAUD};
use ohaca_host::replan::{drive, DevicePlanner, Drive, HostPlanner, Planner, Scenario};
use ohaca_host::{exit, strip, ParamArgs};
use serde::Serialize;

use super::{bad_input, print};

/// Arguments of `ohaca replan`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub input: MapArgs,
    /// The changes: a JSON file (see `docs/HOST.md`, `ohaca replan`)
    #[arg(long, value_name = "FILE")]
    pub events: PathBuf,
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
    iterations: u16,
    moves: u64,
    ticks: Option<u64>,
    raw_length: f32,
    length: f32,
    optimum: Option<f64>,
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
            warm: s.plan.warm,
            iterations: s.plan.iterations,
            moves: s.plan.moves,
            ticks: s.plan.ticks,
            raw_length: s.plan.raw_length,
            length: s.plan.length,
            optimum: s.optimum,
        })
        .collect()
}

/// A device over `link`, told the parameters.
fn device<T: Transport + 'static>(
    mut link: Link<T>,
    params: &Params,
) -> Result<Box<dyn Planner>, String> {
    link.hello().map_err(|e| e.to_string())?;
    link.set_params(params).map_err(|e| e.to_string())?;
    Ok(Box::new(DevicePlanner { link }))
}

fn planner(args: &Args) -> Result<Box<dyn Planner>, String> {
    let params = args.params.params();
    let timeout = Duration::try_from_secs_f64(args.timeout).map_err(|e| e.to_string())?;
    if let Some(addr) = &args.tcp {
        return device(
            Link::tcp(addr, timeout).map_err(|e| e.to_string())?,
            &params,
        );
    }
    if let Some(port) = &args.serial {
        let link = Link::serial(port, args.baud, timeout).map_err(|e| e.to_string())?;
        return device(link, &params);
    }
    Ok(match args.board {
        None => Box::new(HostPlanner::new(params)),
        Some(b) => Box::new(HostPlanner::on(params, b.board())),
    })
}

fn table(rows: &[Row]) -> String {
    let mut out = String::from(
        "mode  plan  robot       changed      warm  iterations  moves      instructions  raw     smoothed  optimum  raw/opt\n",
    );
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
        out += &format!(
            "{:<5} {:<5} {:<11} {:<12} {:<5} {:<11} {:<10} {:<13} {:<7.2} {:<9.2} {:<8} {}\n",
            r.mode,
            r.plan,
            format!("({},{})", r.robot[0], r.robot[1]),
            changed,
            if r.warm { "yes" } else { "no" },
            r.iterations,
            r.moves,
            instr,
            r.raw_length,
            r.length,
            opt,
            ratio
        );
    }
    out
}

/// Run `ohaca replan`; returns the exit code.
pub fn run(args: &Args) -> u8 {
    let sc = match args.input.load() {
        Ok(s) => s,
        Err(e) => return bad_input(e),
    };
    let events = match std::fs::read_to_string(&args.events)
        .map_err(|e| e.to_string())
        .and_then(|t| Scenario::parse(&t))
    {
        Ok(e) => e,
        Err(e) => return bad_input(format_args!("{}: {e}", args.events.display())),
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
    for &(name, warm) in modes {
        match drive(&events, &sc.map, ends, p.as_mut(), warm) {
            Ok(d) => {
                all.extend(rows(name, &d));
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
        if args.compare {
            print(&summary(&all));
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
