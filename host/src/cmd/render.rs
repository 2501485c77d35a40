//! `ohaca render`: plan with one or more algorithms and draw the map with their paths into an
//! SVG or PNG file (see [`ohaca_host::draw`]). Several `--algorithm` values overlay their paths,
//! each in its colour, with a legend; `--pheromone` draws the final pheromone of the first
//! algorithm as a heat map under them.
//!
//! Exit codes: 0 every algorithm found a path; 1 some did not (the picture is written anyway);
//! 2 bad input (map, parameters, start/goal, the output file's name), one line on stderr.

use std::path::PathBuf;

use ohaca::Algorithm;
use ohaca_host::board::{BoardArg, BoardStorage};
use ohaca_host::draw::{self, Layer, Scene};
use ohaca_host::experiment::params_brief;
use ohaca_host::input::{MapArgs, MultiParamArgs, Scenario};
use ohaca_host::plan_map::Lend;
use ohaca_host::trace::{cell_pheromone, plan_traced};
use ohaca_host::{exit, HeapStorage};

use super::bad_input;
use super::plan::plan_error;

/// Arguments of `ohaca render`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub input: MapArgs,
    /// The picture to write: a name ending in .svg or .png
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Draw the final pheromone of the first algorithm as a heat map under the paths
    #[arg(long)]
    pub pheromone: bool,
    /// Plan exactly as this board's firmware does (its buffers, layout and path bound; the same
    /// path as `ohaca send` to it): f411 (also the default QEMU firmware) or h743 (also its QEMU
    /// twin) [default: the host's own storage, every buffer for the map]
    #[arg(long, value_enum, value_name = "BOARD")]
    pub board: Option<BoardArg>,
    #[command(flatten)]
    pub params: MultiParamArgs,
}

/// Run `ohaca render`; returns the exit code.
pub fn run(args: &Args) -> u8 {
    if draw::Format::of(&args.out).is_none() {
        return bad_input(format_args!(
            "{}: the picture's name must end in .svg or .png",
            args.out.display()
        ));
    }
    let sc = match args.input.load() {
        Ok(s) => s,
        Err(e) => return bad_input(e),
    };
    let base = args.params.params.params();
    let algorithms = args.params.algorithms(&[base.algorithm]);
    let mut storage: Box<dyn Lend> = match args.board {
        None => Box::new(HeapStorage::default()),
        Some(b) => {
            let iterations = usize::from(base.iterations);
            match BoardStorage::new(b.board(), sc.map.cells(), iterations) {
                Ok(s) => Box::new(s),
                Err(e) => return bad_input(plan_error(&sc, &e.into())),
            }
        }
    };
    let mut layers = Vec::new();
    let mut pheromone = None;
    let mut all_found = true;
    let mut found = 0usize;
    for (i, &algorithm) in algorithms.iter().enumerate() {
        let params = ohaca::Params { algorithm, ..base };
        let want = args.pheromone && i == 0;
        let t = match plan_traced(storage.as_mut(), &sc.map, sc.start, sc.goal, &params, want) {
            Ok(t) => t,
            Err(e) => return bad_input(plan_error(&sc, &e)),
        };
        all_found &= t.report.found;
        found += usize::from(t.report.found);
        if let Some(tau) = &t.pheromone {
            pheromone = Some(cell_pheromone(tau, sc.map.width, sc.map.height));
        }
        layers.push(Layer::from_report(
            algorithm,
            &t.report,
            sc.metric.map(|f| f.resolution),
        ));
    }
    let scene = scene(&sc, &base, &algorithms, layers, pheromone);
    if let Err(e) = draw::save(&scene, &args.out) {
        return bad_input(e);
    }
    // Say what was written (render used to be silent on success).
    println!(
        "wrote {} ({} of {} planners found a path)",
        args.out.display(),
        found,
        algorithms.len()
    );
    if all_found {
        exit::FOUND
    } else {
        exit::NO_PATH
    }
}

fn scene(
    sc: &Scenario,
    params: &ohaca::Params,
    algorithms: &[Algorithm],
    layers: Vec<Layer>,
    pheromone: Option<Vec<f32>>,
) -> Scene {
    let names: Vec<String> = algorithms.iter().map(|&a| draw::display_name(a)).collect();
    let size = match sc.metric {
        Some(f) => format!(
            "{}x{} cells of {} m",
            sc.map.width, sc.map.height, f.resolution
        ),
        None => format!("{}x{} cells", sc.map.width, sc.map.height),
    };
    Scene {
        title: format!(
            "{}: {} from ({},{}) to ({},{})",
            sc.name,
            names.join(", "),
            sc.start.x,
            sc.start.y,
            sc.goal.x,
            sc.goal.y
        ),
        subtitle: format!("{size}; seed {}, {}", params.seed, params_brief(params)),
        map: sc.map.clone(),
        start: sc.start,
        goal: sc.goal,
        layers,
        pheromone,
        pheromone_label: algorithms
            .first()
            .map(|&a| format!("of {}, after its last iteration", draw::display_name(a)))
            .unwrap_or_default(),
        metric: sc.metric,
    }
}
