//! A walk of the colony's iteration within the pieces' budget: the budget itself (moves a piece,
//! and what starting a walk, tightening, depositing and a flood fill are charged), the walk in
//! progress ([`Going`]: the ant walking, then its path's tightening), and the walk again of a
//! [`Replay`] for the wolves rule. What it guarantees: a walk split over pieces makes the moves
//! and draws of one walk, and a tightening ends its piece leaving the budget the path's deposit
//! needs. No panic, no allocation.

use crate::colony::ant::{Ant, Lost, Trail, Walk};
use crate::colony::tabu::TabuSet;
use crate::colony::tighten::Tightening;
use crate::map::grid::{Dir, Point};
use crate::planner::Shortfalls;
use crate::rng::Xoshiro128pp;

/// Moves of the ants' walks (forward or back) one piece of the colony makes at most
/// ([`Run::poll`]); starting a walk (a pass over the tabu set's words), tightening and depositing
/// a path, and the flood fill of an ant that outgrew its tour are charged on the same budget
/// (`start_cost`, [`UNITS_A_MOVE`], [`PATH_COST`], [`FILL_CELLS`]). Measured under `-icount`
/// (`scripts/bench_pieces.py`, `BENCHMARKS.md` 4d): the largest walk piece is 0.64-0.92 M
/// instructions on NewYork, the depot and Sydney (2,048 moves gave 0.96 M on NewYork). A long
/// path's tightening goes on over as many pieces as it needs ([`Tightening`]: in one piece it was
/// 1.5 M on maze512's 4,000-step path).
/// How to walk one ant of an iteration again: the generator's state before its walk and its move
/// budget. The pheromone, the pruning marks and the route do not change during an iteration (the
/// ants deposit into the increments), so the same state gives the same walk, bit for bit.
#[derive(Clone, Debug)]
pub(super) struct Replay {
    pub(super) rng: Xoshiro128pp,
    pub(super) budget: u32,
}

pub(super) const MOVES_A_PIECE: u32 = 1536;
/// Moves a walk's start is charged for: its copy of the pruning marks into the tabu set, one word
/// for 32 cells (a 512 x 512 map: 8,192 words, as much as about 512 moves).
pub(super) const fn start_cost(cells: usize) -> u32 {
    let words = cells / 32 / 16;
    if words > u32::MAX as usize {
        u32::MAX
    } else {
        words as u32
    }
}
/// Cells of the flood fill a move of the budget pays for (a cell costs about 15 instructions, a
/// move a few hundred).
pub(super) const FILL_CELLS: usize = 32;
/// Path steps a move of the budget pays for in depositing a path.
const PATH_COST: usize = 2;
/// Work units of a path's tightening ([`Tightening::resume`]) a move of the budget pays for.
/// Measured under `-icount` (`scripts/bench_pieces.py`): a unit is about 90 instructions, and the
/// largest piece on maze512 (a 4,000-step path tightened over several pieces) is 0.73-0.75 M at
/// 5 units a move (0.69 M at 4, 1.05 M at 8).
const UNITS_A_MOVE: u32 = 5;
/// The most of a piece's budget the deposit of a path whose tightening ends in it may need: the
/// tightening leaves that much ([`go`]), so the deposit after it stays inside the piece.
const DEPOSIT_RESERVE: u32 = MOVES_A_PIECE / 4;

/// A walk in progress: the ant walking, then its path's tightening.
#[derive(Clone, Debug)]
pub(super) enum Going {
    /// The ant walks: where it stands.
    Walk(Trail),
    /// Its path is tightened: where that stands.
    Tighten(Tightening),
}

/// Go on with the walk `going` of `ant` on the piece's budget `left`, then tighten its path
/// ([`Tightening`]) when `tight` and the walk may have a shortcut: `Ok(Some(walk))` once that is
/// done (the path the ant deposits on, in `tour`), `Ok(None)` when the piece's budget ran out
/// first (where it stands in `going`), `Err` when the ant was lost. The tightening leaves the
/// budget the path's deposit needs ([`DEPOSIT_RESERVE`] at most) and ends the piece rather than
/// eat into it.
#[allow(clippy::too_many_arguments)]
pub(super) fn go(
    ant: &Ant<'_, '_, '_>,
    tight: bool,
    going: &mut Going,
    rng: &mut Xoshiro128pp,
    tabu: &mut TabuSet<'_>,
    tour: &mut [Dir],
    (points, links): (&mut [Point], &mut [u32]),
    left: &mut u32,
    short: &mut Shortfalls,
) -> Result<Option<Walk>, Lost> {
    loop {
        match going {
            Going::Walk(trail) => {
                let Some(walk) = ant.resume(trail, rng, tabu, tour, left)? else {
                    return Ok(None);
                };
                if !(tight && walk.may_tighten) {
                    return Ok(Some(walk));
                }
                match Tightening::begin(ant.moves, ant.start, walk, tour, points, links) {
                    Some(t) => *going = Going::Tighten(t),
                    None => {
                        // No index holds the path: it stays as the ant walked it.
                        short.insert(Shortfalls::TIGHTEN);
                        return Ok(Some(walk));
                    }
                }
            }
            Going::Tighten(t) => {
                let reserve = deposit_cost(t.steps()).min(DEPOSIT_RESERVE);
                let Some(spare) = left.checked_sub(reserve).filter(|&s| s > 0) else {
                    *left = 0;
                    return Ok(None);
                };
                let mut units = spare.saturating_mul(UNITS_A_MOVE);
                let done = t.resume(ant.moves, ant.start, tour, points, links, tabu, &mut units);
                *left = match done {
                    Some(_) => reserve.saturating_add(units / UNITS_A_MOVE),
                    None => 0,
                };
                return Ok(done);
            }
        }
    }
}

/// Moves of the budget the deposit of a path of `steps` steps costs.
fn deposit_cost(steps: usize) -> u32 {
    u32::try_from(steps / PATH_COST).unwrap_or(u32::MAX)
}

/// Charge the deposit of `steps` path steps on the piece's budget `left`.
pub(super) fn charge(left: &mut u32, steps: usize) {
    *left = left.saturating_sub(deposit_cost(steps));
}

/// Walk the ant of `r` again into `buf` (the path it deposited on, tightened), a piece at a time:
/// `None` while it pauses (its state in `slot`), then whether it gave the path of `steps` steps
/// again (always, unless there is no replay).
#[allow(clippy::too_many_arguments)]
pub(super) fn again(
    ant: &mut Ant<'_, '_, '_>,
    tight: bool,
    r: &Option<Replay>,
    steps: usize,
    slot: &mut Option<(Going, Xoshiro128pp)>,
    tabu: &mut TabuSet<'_>,
    buf: &mut [Dir],
    index: (&mut [Point], &mut [u32]),
    left: &mut u32,
) -> Option<bool> {
    let Some(r) = r else { return Some(false) };
    let (mut going, mut rng) = match slot.take() {
        Some(s) => s,
        None => {
            *left = left.saturating_sub(start_cost(ant.moves.grid().cells()));
            (Going::Walk(ant.begin(tabu, buf)), r.rng.clone())
        }
    };
    ant.budget = r.budget;
    // The walk again is the first: a shortfall was counted then.
    let mut short = Shortfalls::NONE;
    let (r, short) = (&mut rng, &mut short);
    match go(ant, tight, &mut going, r, tabu, buf, index, left, short) {
        Ok(None) => {
            *slot = Some((going, rng));
            None
        }
        Ok(Some(w)) => Some(w.steps == steps),
        Err(_) => Some(false),
    }
}
