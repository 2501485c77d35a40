//! The checks behind every fuzz target, as plain functions so the same inputs can be replayed
//! from tests (`cargo test` in this crate runs the saved regression inputs).
//!
//! * [`fuzz_planner`] — the `planner` target (below).
//! * [`wire_frame::fuzz_wire_frame`] — the `wire_frame` target: the protocol's frame readers and
//!   decoders.
//! * [`maps::fuzz_map_parsers`] — the `map_parsers` target: the host tool's map readers.

pub mod maps;
pub mod wire_frame;

use arbitrary::{Arbitrary, Unstructured};
use ohaca::geometry::{polyline_length, segment_clear, steps_length};
use ohaca::grid::{is_diagonal, Grid, Point};
use ohaca::planner::{Area, Buffers, CurvePoint, Memory, Plan, Poll, Run, Workspace};
use ohaca::{Algorithm, DeadEnd, Error, Params, SmoothingKind};

/// A planner input: a small map, endpoints and parameters including extremes.
#[derive(Debug)]
pub struct PlannerInput {
    pub width: u16,
    pub height: u16,
    pub bits: Vec<u8>,
    pub start: Point,
    pub goal: Point,
    pub params: Params,
    /// A replan after the first plan: cells flipped (blocked or cleared), then `PlanWarm` from a
    /// new start to the same goal, on the colony the first plan left.
    pub replan: Option<Replan>,
}

/// Cell changes and a warm replan (see [`PlannerInput::replan`]).
#[derive(Debug)]
pub struct Replan {
    pub changes: Vec<(Point, bool)>,
    pub start: Point,
}

fn pick_f32(u: &mut Unstructured<'_>, choices: &[f32]) -> arbitrary::Result<f32> {
    // Mostly interesting fixed values, sometimes raw bits (NaN, inf, subnormal, huge).
    if u.ratio(1, 4)? {
        Ok(f32::from_bits(u32::arbitrary(u)?))
    } else {
        Ok(*u.choose(choices)?)
    }
}

impl<'a> Arbitrary<'a> for PlannerInput {
    fn arbitrary(u: &mut Unstructured<'a>) -> arbitrary::Result<Self> {
        let width = u.int_in_range(1..=20u16)?;
        let height = u.int_in_range(1..=20u16)?;
        let cells = usize::from(width) * usize::from(height);
        let mut bits = vec![0u8; cells.div_ceil(8)];
        u.fill_buffer(&mut bits)?;
        // Thin the obstacles out so paths exist often.
        let density = u.int_in_range(0..=3u8)?;
        for b in bits.iter_mut() {
            for _ in 0..density {
                *b &= u8::arbitrary(u)?;
            }
        }
        let start = Point::new(u.int_in_range(0..=width)?, u.int_in_range(0..=height)?);
        let goal = Point::new(u.int_in_range(0..=width)?, u.int_in_range(0..=height)?);
        let algorithm = *u.choose(&Algorithm::ALL)?;
        let params = Params {
            algorithm,
            ants: *u.choose(&[0u16, 1, 2, 5, 50])?,
            iterations: *u.choose(&[0u16, 1, 2, 10])?,
            alpha: pick_f32(u, &[0.0, 1.0, 2.0, 0.5, 16.0, 17.0])?,
            beta: pick_f32(u, &[0.0, 1.0, 2.0, 16.0, -1.0])?,
            rho: pick_f32(u, &[0.1, 1.0, 0.0, 1e-7])?,
            q: pick_f32(u, &[1.0, 1e30, 1e-30, 0.0])?,
            a: pick_f32(u, &[0.05, 1.0, 1e-30, 0.999])?,
            xi: pick_f32(u, &[1.0, 0.0, 1e6])?,
            tau0: pick_f32(u, &[1.0, 0.01, 100.0])?,
            tau_min: pick_f32(u, &[0.01, 1e-30, 1.0])?,
            tau_max: pick_f32(u, &[100.0, 1e30, 1.0])?,
            patience: *u.choose(&[0u16, 1, 20])?,
            warm_patience: *u.choose(&[0u16, 1, 3])?,
            refine_patience: 0,
            seed: u64::arbitrary(u)?,
            dead_end: if bool::arbitrary(u)? {
                DeadEnd::Backtrack
            } else {
                DeadEnd::Die
            },
            smoothing: *u.choose(&[
                SmoothingKind::Shortest,
                SmoothingKind::Greedy,
                SmoothingKind::None,
            ])?,
            tighten: bool::arbitrary(u)?,
            prune: bool::arbitrary(u)?,
            refine: false,
        };
        let replan = if bool::arbitrary(u)? {
            let n = u.int_in_range(0..=12usize)?;
            let mut changes = Vec::with_capacity(n);
            for _ in 0..n {
                let p = Point::new(u.int_in_range(0..=width)?, u.int_in_range(0..=height)?);
                changes.push((p, bool::arbitrary(u)?));
            }
            let start = Point::new(u.int_in_range(0..=width)?, u.int_in_range(0..=height)?);
            Some(Replan { changes, start })
        } else {
            None
        };
        // Decoded last, so that older inputs (which run out of bytes before) keep their meaning:
        // the local search and its patience, and a tiling of the map (up to 60 x 60 cells) so
        // that it applies (maps of more than 1,024 cells).
        let mut params = params;
        params.refine = bool::arbitrary(u)?;
        params.refine_patience = *u.choose(&[0u16, 1, 3])?;
        let tile = u.int_in_range(1..=3u16)?;
        let (width, height, bits) = tiled(width, height, &bits, tile);
        Ok(PlannerInput {
            width,
            height,
            bits,
            start,
            goal,
            params,
            replan,
        })
    }
}

/// The map `bits` (`w x h`) repeated `t x t` times.
fn tiled(w: u16, h: u16, bits: &[u8], t: u16) -> (u16, u16, Vec<u8>) {
    if t <= 1 {
        return (w, h, bits.to_vec());
    }
    let (tw, th) = (w * t, h * t);
    let (w, h, tw_) = (usize::from(w), usize::from(h), usize::from(tw));
    let mut out = vec![0u8; (tw_ * usize::from(th)).div_ceil(8)];
    for y in 0..usize::from(th) {
        for x in 0..tw_ {
            let i = (y % h) * w + x % w;
            if bits.get(i / 8).is_some_and(|b| b & (1 << (i % 8)) != 0) {
                let j = y * tw_ + x;
                out[j / 8] |= 1 << (j % 8);
            }
        }
    }
    (tw, th, out)
}

/// Plan and check every promise the planner makes, then (if asked) change cells and replan warm
/// on the same buffers and check again. Panics (= a fuzz finding) on a broken promise.
pub fn check_planner(input: &PlannerInput) {
    let (w, h) = (input.width, input.height);
    if Grid::new(w, h, &input.bits).is_err() {
        return;
    }
    let cells = usize::from(w) * usize::from(h);
    let blocks = cells.min(ohaca::pheromone::BLOCKS);
    let guide = ohaca::route::GUIDE_BLOCKS;
    let mut tau = vec![[0f32; 4]; blocks];
    let mut delta = vec![[0f32; 4]; blocks];
    let mut tabu = vec![0u32; ohaca::bitmap::words(cells)];
    let mut dead = vec![0u32; ohaca::bitmap::words(cells)];
    let mut moves = vec![0u8; cells];
    let mut tours: Vec<Vec<u8>> = (0..4).map(|_| vec![0u8; cells]).collect();
    let mut points = vec![Point::default(); cells + 1];
    let mut links = vec![0u32; cells.max(guide)];
    let mut curve = vec![CurvePoint::default(); 16];
    let mut guide_words = vec![0u32; guide];
    let mut bits = input.bits.clone();
    let mut memory = Memory::new();
    let p = &input.params;
    let rounds = [(input.start, false)]
        .into_iter()
        .chain(input.replan.as_ref().map(|r| (r.start, true)));
    for (start, warm) in rounds {
        if warm {
            for &(c, blocked) in input.replan.iter().flat_map(|r| &r.changes) {
                // The device's cell writer; a cell off the map changes nothing.
                if ohaca::protocol::set_rect((w, h), &mut bits, (c.x, c.y, 1, 1), blocked).is_ok() {
                    // A cleared cell is reported as cleared (what the firmware's receiver does).
                    let cleared = (!blocked).then_some(Area::cell(c));
                    memory.changed(Area::cell(c), cleared);
                }
            }
        }
        let Ok(grid) = Grid::new(w, h, &bits) else {
            return;
        };
        let [t0, t1, t2, t3] = &mut tours[..] else {
            return;
        };
        let ws = Workspace::new(Buffers {
            tau: &mut tau,
            delta: &mut delta,
            tabu: &mut tabu,
            dead: &mut dead,
            moves: &mut moves,
            tours: [t0, t1, t2, t3],
            points: &mut points,
            links: &mut links,
            curve: &mut curve,
            guide: &mut guide_words,
        });
        let was_warm = memory.is_warm_for(w, h, input.goal);
        let result = if warm {
            Run::warm(&grid, start, input.goal, p, ws, &mut memory)
        } else {
            Run::cold(&grid, start, input.goal, p, ws, &mut memory)
        }
        .and_then(|mut run| {
            assert_eq!(
                run.is_warm(),
                warm && was_warm,
                "warm exactly when the memory matches"
            );
            while let Poll::Working(_) = run.poll() {}
            run.finish()
        });
        check_result(&grid, start, input.goal, p, result);
    }
}

/// Check one plan's result against every promise the planner makes.
fn check_result(
    grid: &Grid<'_>,
    start: Point,
    goal: Point,
    p: &Params,
    result: Result<Plan<'_>, Error>,
) {
    let cells = grid.cells();
    match result {
        Ok(plan) => {
            let raw: Vec<Point> = plan.raw().collect();
            assert_eq!(raw.first(), Some(&start));
            assert_eq!(raw.last(), Some(&goal));
            for (w, &d) in raw.windows(2).zip(plan.directions()) {
                assert_eq!(
                    grid.step(w[0], d),
                    Some(w[1]),
                    "raw path leaves the allowed moves"
                );
            }
            let diag = plan
                .directions()
                .iter()
                .filter(|&&d| is_diagonal(d))
                .count() as u32;
            let straight = plan.directions().len() as u32 - diag;
            assert_eq!(plan.raw_length, steps_length(straight, diag));
            let wp = plan.waypoints();
            assert_eq!(wp.first(), Some(&start));
            assert_eq!(wp.last(), Some(&goal));
            for s in wp.windows(2) {
                assert!(
                    segment_clear(grid, s[0], s[1]),
                    "smoothed segment {s:?} touches an obstacle"
                );
            }
            assert!(plan.length <= plan.raw_length + 1e-3 * (1.0 + plan.raw_length));
            // Unsmoothed (every algorithm but OHACA, or smoothing off), the planner reports the
            // exact step-count length, which a re-summed polyline can miss in the last bit
            // (`Run::finish` in src/planner.rs; regressions/planner/unsmoothed-length-is-step-count).
            let unsmoothed = p.algorithm != Algorithm::Ohaca || p.smoothing == SmoothingKind::None;
            if unsmoothed {
                assert_eq!(
                    plan.length, plan.raw_length,
                    "unsmoothed length is the raw length"
                );
                let summed = polyline_length(wp);
                assert!(
                    (plan.length - summed).abs() <= 1e-5 * (1.0 + summed),
                    "{summed}"
                );
            } else {
                assert_eq!(plan.length, polyline_length(wp));
            }
            // Termination bound: every ant moves at most 2 * cells times.
            let bound = u64::from(p.ants) * u64::from(p.iterations) * 2 * cells as u64;
            assert!(plan.moves <= bound, "{} moves > bound {bound}", plan.moves);
            assert!(plan.iterations <= p.iterations);
        }
        Err(Error::BadParam(_)) => assert!(p.validate().is_err()),
        Err(e @ (Error::NoPath | Error::NoAntArrived)) => {
            let mut m = vec![0u32; ohaca::bitmap::words(cells)];
            let mut q = vec![0u32; cells];
            let scratch = ohaca::grid::FillScratch::new(&mut m, &mut q);
            let reachable = grid.reachable(start, goal, scratch) == ohaca::grid::Reach::Yes;
            if e == Error::NoPath {
                assert!(!reachable, "NoPath on a reachable goal");
            } else {
                assert!(
                    reachable && p.dead_end == DeadEnd::Die,
                    "NoAntArrived without dying ants"
                );
            }
        }
        Err(Error::OutOfBounds(_)) => {
            assert!(!grid.contains(start) || !grid.contains(goal))
        }
        Err(Error::Blocked(_)) => assert!(!grid.is_free(start) || !grid.is_free(goal)),
        Err(e) => panic!("unexpected error {e}"),
    }
}

/// Decode raw fuzzer bytes into a planner input and check it.
pub fn fuzz_planner(data: &[u8]) {
    let mut u = Unstructured::new(data);
    if let Ok(input) = PlannerInput::arbitrary(&mut u) {
        check_planner(&input);
    }
}
