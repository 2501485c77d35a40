//! One ant's walk from start to goal: the transition rule (paper eq. 5/14), the tabu list, and
//! what happens at a dead end.
//!
//! From cell `i` the ant may move to every neighbour `j` that the grid allows (no corner cutting)
//! and that it has not visited yet (the tabu list). It picks `j` with probability proportional to
//! `tau_ij^alpha * eta_ij^beta` (roulette wheel, one uniform draw). If it has no allowed move:
//!
//! - [`DeadEnd::Backtrack`] (default): it steps back along its own path and tries again from there,
//!   keeping the tabu list, so the dead-end branch is never re-entered. The walk is then a
//!   randomised depth-first search, which reaches the goal whenever it is reachable, and the
//!   recorded path (the search stack) is a simple path without loops.
//! - [`DeadEnd::Die`]: the ant is discarded for this iteration, as in the paper.
//!
//! Bound: every cell is entered at most once and left backwards at most once, so a walk takes at
//! most `2 * cells` steps.
//!
//! The path is recorded as one direction byte per step, so a tour costs one byte per step whatever
//! the map size.
//!
//! A walk can be done a bounded number of moves at a time ([`Ant::begin`], [`Ant::resume`]: the
//! planner's pieces, `planner::run`): its state between pieces is a [`Trail`], and the pieces
//! make the same moves with the same draws as one [`Ant::walk`], bit for bit.
//!
//! Two loops make the moves: a general one, and one for maps whose pheromone has an entry a cell
//! and no route (the pheromone's block shift 0: in the planner's workspaces every map of at most
//! [`crate::colony::pheromone::BLOCKS`] cells, the paper preset's), which finds a move's pheromone at a fixed offset from its cell's and keeps the
//! weights by direction. Both make the same moves with the same draws, bit for bit (the same
//! products, summed in the same order; a test compares them on random maps, pheromone, budgets
//! and pieces).

use crate::colony::heuristic::Heuristic;
use crate::colony::pheromone::{slot_offsets, Table};
use crate::colony::route::Route;
use crate::colony::tabu::TabuSet;
#[cfg(any(feature = "alloc", test))]
use crate::colony::weights::WeightTable;
use crate::map::bitmap;
use crate::map::grid::{is_diagonal, neighbour, opposite, Dir, Moves, Point, DX, DY};
use crate::named::named;
use crate::rng::Xoshiro128pp;

mod cells;

/// What an ant does when every neighbour is blocked or already visited.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "lowercase")
)]
pub enum DeadEnd {
    /// Step back along its path and continue (never loses an ant while the goal is reachable).
    #[default]
    Backtrack,
    /// The paper's behaviour: the ant dies and contributes nothing this iteration.
    Die,
}

named!(DeadEnd, "Both, default first.", [Backtrack => "backtrack", Die => "die"]);

/// A finished walk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Walk {
    /// Steps on the recorded path (the first `steps` bytes of the tour buffer).
    pub steps: usize,
    /// Straight steps on the path.
    pub straight: u32,
    /// Diagonal steps on the path.
    pub diagonal: u32,
    /// Moves made, counting forward steps and backtracking steps.
    pub moves: u32,
    /// The walk passed next to a cell it had visited before (other than the one it came from),
    /// so [`crate::colony::tighten::tighten`] may find a shortcut; when false, tightening cannot change the path.
    pub may_tighten: bool,
}

/// Where a walk stands between two pieces ([`Ant::begin`], [`Ant::resume`]): its cell, its
/// path's length, its moves so far, and the sub-goal it pulls toward. The tabu set and the tour
/// hold the rest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Trail {
    cur: Point,
    ci: usize,
    steps: usize,
    moves: u32,
    may_tighten: bool,
    block: usize,
    target: Point,
}

/// What the tour's last slot holds until the path fills the tour (no direction is 255).
const UNFILLED: Dir = 0xFF;

/// Why a walk ended without reaching the goal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lost {
    /// [`DeadEnd::Die`]: the ant died at a dead end.
    Died,
    /// The path would grow longer than the tour buffer holds: a dying ant is dropped there; a
    /// backtracking one takes each cell it cannot step into for that reason for a wall and ends
    /// with this only when it found no way within the tour's length (nothing proved).
    Overflow,
    /// [`DeadEnd::Backtrack`]: the ant backed out of every branch to the start: the goal is not
    /// reachable (a proof, since pruned cells never disconnect the start from the goal).
    Exhausted,
    /// The walk made more moves than [`Ant::budget`] allows and was abandoned: no proof of
    /// anything, the ant simply costs no more.
    Budget,
}

/// Everything an ant reads; borrowed for one iteration.
pub struct Ant<'g, 't, 'h> {
    /// The map's allowed moves.
    pub moves: &'g Moves<'g>,
    /// Start cell.
    pub start: Point,
    /// Goal cell.
    pub goal: Point,
    /// Pheromone, read only during construction.
    pub tau: &'t Table<'t>,
    /// `eta^beta` table.
    pub heuristic: &'h Heuristic,
    /// Pheromone exponent.
    pub alpha: f32,
    /// Dead-end behaviour.
    pub dead_end: DeadEnd,
    /// Cells no ant enters ([`crate::map::prune`]); every walk's tabu list starts as this set. Empty:
    /// none (a workspace without pruning marks).
    pub dead: &'t [u32],
    /// Sub-goals of the potential field on large maps ([`crate::colony::route`]); `None`: the goal.
    pub route: Option<&'t Route<'t>>,
    /// The iteration's weights by cell and direction ([`crate::colony::weights`]), filled as the
    /// ants first have a choice on a cell, read by the loop for an entry a cell (the pheromone's
    /// block shift 0, no route; ignored elsewhere); `None`: each move computes its weights. The
    /// same walks either way, bit for bit. Where a heap storage can lend one (feature `alloc`):
    /// the device's builds carry no table, and their frames and code are as without it.
    #[cfg(any(feature = "alloc", test))]
    pub weights: Option<&'t WeightTable<'t>>,
    /// Most moves (forward and back) the walk may make; one that needs more is abandoned
    /// ([`Lost::Budget`]). `u32::MAX`: no bound, the walk goes on until it arrives or exhausts.
    pub budget: u32,
}

/// `tau^alpha` with the common exponents done without `powf`.
#[inline]
fn pow_alpha(tau: f32, alpha: f32) -> f32 {
    if alpha == 1.0 {
        tau
    } else if alpha == 0.0 {
        1.0
    } else if alpha == 2.0 {
        tau * tau
    } else {
        libm::powf(tau, alpha)
    }
}

impl Ant<'_, '_, '_> {
    /// Walk one ant. `tabu` holds at least the map's cells ([`TabuSet::of`]; its content is
    /// replaced: it starts as the dead cells); `tour` receives the directions and bounds the path's
    /// length.
    pub fn walk(
        &self,
        rng: &mut Xoshiro128pp,
        tabu: &mut TabuSet<'_>,
        tour: &mut [Dir],
    ) -> Result<Walk, Lost> {
        let mut trail = self.begin(tabu, tour);
        loop {
            let mut left = u32::MAX;
            if let Some(walk) = self.resume(&mut trail, rng, tabu, tour, &mut left)? {
                return Ok(walk);
            }
        }
    }

    /// Start a walk to be done a piece at a time ([`Ant::resume`]): the tabu set becomes the dead
    /// cells and the start (a pass over the set's words), the ant stands at the start.
    pub fn begin(&self, tabu: &mut TabuSet<'_>, tour: &mut [Dir]) -> Trail {
        let grid = self.moves.grid();
        tabu.reset(grid.cells(), self.dead);
        let ci = grid.index(self.start);
        // The tour's last slot, unwritten until the path fills the tour: only then can a cell be
        // refused for the tour's length (below), and a walk that backs out of everything proves
        // nothing. A mark in the buffer, not a flag in the loop: the loop keeps its registers.
        if let Some(last) = tour.last_mut() {
            *last = UNFILLED;
        }
        tabu.insert(ci);
        Trail {
            cur: self.start,
            ci,
            steps: 0,
            moves: 0,
            may_tighten: false,
            // The sub-goal changes only when the ant enters another block.
            block: usize::MAX,
            target: self.goal,
        }
    }

    /// Go on with the walk at `trail` ([`Ant::begin`]) for at most `left` moves (forward or back;
    /// `left` is decreased by the moves made; a cell refused for the tour's length is not a move,
    /// and marks a cell, so there are fewer of those than cells): `Ok(Some(walk))` once
    /// it arrived, `Ok(None)` when it paused (`trail` says where; resume with the same `rng`,
    /// `tabu` and `tour`), `Err` when it ended without arriving. The pieces together make the
    /// moves and draws of one [`Ant::walk`].
    pub fn resume(
        &self,
        trail: &mut Trail,
        rng: &mut Xoshiro128pp,
        tabu: &mut TabuSet<'_>,
        tour: &mut [Dir],
        left: &mut u32,
    ) -> Result<Option<Walk>, Lost> {
        let cells = self.route.is_none() && self.tau.blocks().shift() == 0;
        #[cfg(any(feature = "alloc", test))]
        if let (true, Some(table)) = (cells, self.weights) {
            return self.resume_table(table, trail, rng, tabu, tour, left);
        }
        self.resume_by(cells, trail, rng, tabu, tour, left)
    }

    /// [`Ant::resume`] by the loop for an entry a cell reading the weights from `table`
    /// ([`Ant::walk_table`]).
    #[cfg(any(feature = "alloc", test))]
    #[inline(never)]
    fn resume_table(
        &self,
        table: &WeightTable<'_>,
        trail: &mut Trail,
        rng: &mut Xoshiro128pp,
        tabu: &mut TabuSet<'_>,
        tour: &mut [Dir],
        left: &mut u32,
    ) -> Result<Option<Walk>, Lost> {
        let alpha = self.alpha;
        if alpha == 1.0 {
            self.walk_table(table, trail, rng, tabu, tour, left, |t| t)
        } else {
            self.walk_table(table, trail, rng, tabu, tour, left, |t| pow_alpha(t, alpha))
        }
    }

    /// [`Ant::resume`] by the loop for an entry a cell ([`Ant::walk_cells`], `cells`: only
    /// where the pheromone has an entry a cell and there is no route) or by the general one.
    fn resume_by(
        &self,
        cells: bool,
        trail: &mut Trail,
        rng: &mut Xoshiro128pp,
        tabu: &mut TabuSet<'_>,
        tour: &mut [Dir],
        left: &mut u32,
    ) -> Result<Option<Walk>, Lost> {
        // The common exponent gets its own copy of each loop, without a test per candidate;
        // `pow_alpha(t, 1.0)` is `t`, so both give the same weights. Each loop is a function of
        // its own, so this one's stack frame is small and the deeper of them is the stack's need.
        let alpha = self.alpha;
        match (cells, alpha == 1.0) {
            (true, true) => self.walk_cells(trail, rng, tabu, tour, left, |t| t),
            (true, false) => self.walk_cells(trail, rng, tabu, tour, left, |t| pow_alpha(t, alpha)),
            (false, true) => self.walk_general(trail, rng, tabu, tour, left, |t| t),
            (false, false) => {
                self.walk_general(trail, rng, tabu, tour, left, |t| pow_alpha(t, alpha))
            }
        }
    }

    /// [`Ant::resume`] by the general loop, with `tau^alpha` computed by `pow`.
    #[inline(never)]
    fn walk_general(
        &self,
        trail: &mut Trail,
        rng: &mut Xoshiro128pp,
        tabu: &mut TabuSet<'_>,
        tour: &mut [Dir],
        limit: &mut u32,
        pow: impl Fn(f32) -> f32,
    ) -> Result<Option<Walk>, Lost> {
        let grid = self.moves.grid();
        let offsets = grid.offsets();
        let blocks = self.tau.blocks();
        let tau = self.tau.flat();
        let goal = grid.index(self.goal);
        let Trail {
            mut cur,
            mut ci,
            mut steps,
            mut moves,
            mut may_tighten,
            mut block,
            mut target,
        } = *trail;
        // Only the first `n` entries are read, each written first in the same step.
        let mut cand_dir = [0u8; 8];
        let mut cand_w = [0.0f32; 8];
        let width = usize::from(grid.width());
        // The walk stops at its budget or after `limit` more moves, whichever comes first.
        let first = moves;
        let stop = self.budget.min(moves.saturating_add(*limit));
        while ci != goal {
            let allowed = self.moves.at(ci, cur);
            // The allowed moves into visited (or pruned) cells: one 3 x 3 read of the tabu set,
            // the border's cells too ([`visited_moves`]).
            let tabu_moves = visited_moves(tabu, ci, allowed, width);
            let step = |d: usize| offsets.get(d).copied().unwrap_or(0);
            // A visited neighbour (not a pruned one) may offer a shortcut: one of them is the
            // cell we came from, a second one may be a shortcut. Once one walk cell had two, the
            // answer is known and the test is skipped.
            if !may_tighten && tabu_moves & tabu_moves.wrapping_sub(1) != 0 {
                may_tighten = self.shortcut_seen(ci, tabu_moves, step);
            }
            let mut mask = allowed & !tabu_moves;
            let mut n = 0usize;
            let mut total = 0.0f32;
            if mask & mask.wrapping_sub(1) == 0 {
                // No open move or exactly one (a corridor, the way back out of a dead end): no
                // weights to compute. A single candidate is taken without a draw, as the roulette
                // below would, so the walk is the same as if its weight had been computed.
                if let Some(cd) = cand_dir.get_mut(0) {
                    *cd = mask.trailing_zeros() as u8 & 7;
                }
                n = usize::from(mask != 0);
                mask = 0;
            }
            // The potential field's row (and the route's sub-goal) only where there is a choice.
            if mask != 0 {
                let eta = match self.route {
                    None => self.heuristic.row(cur),
                    Some(r) => {
                        // The sub-goal depends on the block only: computed when the ant chooses
                        // in another block than last time.
                        let b = r.block(cur);
                        if b != block {
                            block = b;
                            target = r.target(cur);
                        }
                        self.heuristic.row_toward(cur, target)
                    }
                };
                let edges = blocks.edges(cur);
                // Visit the open moves only (set bits of the mask, lowest first).
                while mask != 0 {
                    // `& 7`: the mask is non-zero, so this is the index itself, and the compiler
                    // knows it is in range for the 8-entry tables below.
                    let di = mask.trailing_zeros() as usize & 7;
                    mask &= mask.wrapping_sub(1); // mask != 0: clears the lowest set bit
                    let ti = edges.get(di).copied().unwrap_or(usize::MAX);
                    let t = tau.get(ti).copied().unwrap_or(0.0);
                    let w = pow(t) * eta.get(di);
                    if let (Some(cd), Some(cw)) = (cand_dir.get_mut(n & 7), cand_w.get_mut(n & 7)) {
                        *cd = di as u8;
                        *cw = w;
                    }
                    total += w;
                    n = n.wrapping_add(1); // at most 8
                }
            }
            moves = moves.saturating_add(1);
            // One test a move for both the walk's budget and the piece's end (`stop`, the
            // smaller of the two).
            if moves > stop {
                if moves > self.budget {
                    *limit = limit.saturating_sub(moves.wrapping_sub(first));
                    return Err(Lost::Budget);
                }
                // The piece is over: this move is made in the next one, which finds the same
                // candidates (nothing above changed the walk but the `may_tighten` it sets
                // again).
                *trail = Trail {
                    cur,
                    ci,
                    steps,
                    moves: moves.wrapping_sub(1),
                    may_tighten,
                    block,
                    target,
                };
                *limit = 0;
                return Ok(None);
            }
            let d = if n == 0 {
                match self.dead_end {
                    DeadEnd::Die => {
                        *limit = limit.saturating_sub(moves.wrapping_sub(first));
                        return Err(Lost::Died);
                    }
                    DeadEnd::Backtrack => {
                        // Back at the start with nothing left: no path, unless the path once
                        // filled the tour, when its length may have cut ways off (then nothing
                        // is proved; the colony's flood fill decides).
                        let Some(s) = steps.checked_sub(1) else {
                            let filled = tour.last().is_none_or(|&d| d != UNFILLED);
                            *limit = limit.saturating_sub(moves.wrapping_sub(first));
                            return Err(if filled {
                                Lost::Overflow
                            } else {
                                Lost::Exhausted
                            });
                        };
                        steps = s;
                        let back = opposite(tour.get(steps).copied().ok_or(Lost::Overflow)?);
                        ci = ci.wrapping_add_signed(
                            offsets.get(usize::from(back)).copied().unwrap_or(0),
                        );
                        cur = neighbour(cur, back);
                        continue;
                    }
                }
            } else if n == 1 {
                cand_dir[0]
            } else {
                let k = roulette(rng, cand_w.get(..n).unwrap_or(&[]), total);
                cand_dir.get(k).copied().unwrap_or(0)
            };
            let Some(slot) = tour.get_mut(steps) else {
                // The path would outgrow the tour. A dying ant is dropped; a backtracking one
                // takes that cell for a wall (tabu for the rest of its walk) and goes on, so a
                // long dead-end branch of a maze costs it the branch, not the walk. Not a move.
                match self.dead_end {
                    DeadEnd::Die => {
                        *limit = limit.saturating_sub(moves.wrapping_sub(first));
                        return Err(Lost::Overflow);
                    }
                    DeadEnd::Backtrack => {
                        let ni = ci
                            .wrapping_add_signed(offsets.get(usize::from(d)).copied().unwrap_or(0));
                        tabu.insert(ni);
                        moves = moves.wrapping_sub(1); // counted above: at least 1
                        continue;
                    }
                }
            };
            *slot = d;
            steps = steps.wrapping_add(1); // < tour.len() + 1: the slot existed
            ci = ci.wrapping_add_signed(offsets.get(usize::from(d)).copied().unwrap_or(0));
            cur = neighbour(cur, d);
            tabu.insert(ci);
        }
        *limit = limit.saturating_sub(moves.wrapping_sub(first));
        self.arrived(tabu, tour, steps, moves, may_tighten)
    }

    /// Whether more than one of the visited neighbours in `tabu_moves` (directions; `step` gives
    /// a direction's index offset) of cell `ci` is a walk cell, not a pruned one: the walk may
    /// then have a shortcut for its tightening.
    #[inline(always)]
    fn shortcut_seen(&self, ci: usize, tabu_moves: u8, step: impl Fn(usize) -> isize) -> bool {
        let mut seen = 0u32;
        let mut m = tabu_moves;
        while m != 0 {
            let di = m.trailing_zeros() as usize & 7;
            m &= m.wrapping_sub(1);
            let ni = ci.wrapping_add_signed(step(di));
            // At most 8: one per bit of the mask.
            seen = seen.wrapping_add(u32::from(!bitmap::marked(self.dead, ni)));
        }
        seen > 1
    }

    /// The walk that reached the goal with `steps` steps in `tour` after `moves` moves.
    #[inline(always)]
    fn arrived(
        &self,
        tabu: &TabuSet<'_>,
        tour: &[Dir],
        steps: usize,
        moves: u32,
        mut may_tighten: bool,
    ) -> Result<Option<Walk>, Lost> {
        let offsets = self.moves.grid().offsets();
        let goal = self.moves.grid().index(self.goal);
        // The loop checks for a second visited neighbour at every cell but the goal; a detour
        // whose only shortcut ends at the goal (e.g. (0,0) -> (0,1) -> (1,0) on an empty map) is
        // caught here.
        if !may_tighten {
            let mut mask = self.moves.at(goal, self.goal);
            let mut seen = 0u32;
            while mask != 0 {
                let di = mask.trailing_zeros() as usize & 7;
                mask &= mask.wrapping_sub(1);
                let ni = goal.wrapping_add_signed(offsets.get(di).copied().unwrap_or(0));
                // At most 8, one per bit of the mask.
                let visited = tabu.contains(ni) && !bitmap::marked(self.dead, ni);
                seen = seen.wrapping_add(u32::from(visited));
            }
            may_tighten = seen > 1;
        }
        let path = tour.get(..steps).ok_or(Lost::Overflow)?;
        let diagonal = path.iter().filter(|&&d| is_diagonal(d)).count() as u32;
        Ok(Some(Walk {
            steps,
            // diagonal <= steps, and steps < cells < 2^32 (each step enters an unvisited cell), so
            // the cast is lossless and the difference does not wrap.
            straight: (steps as u32).wrapping_sub(diagonal),
            diagonal,
            moves,
            may_tighten,
        }))
    }
}

/// The `allowed` moves of cell `ci` into cells of the tabu set (visited or pruned), as a
/// direction mask: one 3 x 3 read of the set around `ci` on a map `width` cells wide, for every
/// cell, the border's too. A neighbour on the map has the index the read takes for it
/// (`ci +- 1`, `ci +- width`, ...); a direction off the map is never allowed (the move masks
/// keep an ant on its map), so what the read finds there (another row's cell, or a cell beyond
/// the words: set) is masked out. So the same mask as a test per allowed move, at one read.
#[inline(always)]
fn visited_moves(tabu: &TabuSet<'_>, ci: usize, allowed: u8, width: usize) -> u8 {
    tabu.around(ci, width) & allowed
}

/// Roulette-wheel choice: index `i` with probability `w[i] / total` (one uniform draw). If every
/// weight underflowed to 0 (or the sum overflowed), choose uniformly instead.
#[inline]
fn roulette(rng: &mut Xoshiro128pp, w: &[f32], total: f32) -> usize {
    let n = w.len();
    // `0 < total <= MAX`: positive and finite (NaN fails both), with two float comparisons
    // (`is_finite` compiles to integer bit tests on the M4).
    if !(total > 0.0 && total <= f32::MAX) {
        // A 32-bit word times n <= 8 candidates: well below 2^64.
        return (u64::from(rng.next_word()).wrapping_mul(n as u64) >> 32) as usize;
    }
    let r = rng.next_unit() * total;
    let mut acc = 0.0f32;
    for (i, wi) in w.iter().enumerate() {
        acc += wi;
        if r < acc {
            return i;
        }
    }
    // Rounding can leave r just above the running sum: take the last candidate.
    n.saturating_sub(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colony::heuristic::Attraction;
    use crate::colony::pheromone::Blocks;
    use crate::map::grid::Grid;

    fn setup(rows: &[&str]) -> (Vec<u8>, u16, u16) {
        crate::testutil::bits(rows)
    }

    fn run(
        rows: &[&str],
        start: Point,
        goal: Point,
        dead_end: DeadEnd,
        seed: u64,
    ) -> Option<(Walk, Vec<u8>)> {
        run_with(rows, start, goal, dead_end, seed, 0.05)
    }

    /// [`run`] with goal-attraction base `a` (1 = no attraction).
    fn run_with(
        rows: &[&str],
        start: Point,
        goal: Point,
        dead_end: DeadEnd,
        seed: u64,
        a: f32,
    ) -> Option<(Walk, Vec<u8>)> {
        let (walk, tour) = walk_on(rows, (start, goal), dead_end, seed, a, u32::MAX);
        walk.ok().map(|w| (w, tour[..w.steps].to_vec()))
    }

    /// One walk with move budget `budget`: its result and the whole tour buffer.
    fn walk_on(
        rows: &[&str],
        (start, goal): (Point, Point),
        dead_end: DeadEnd,
        seed: u64,
        a: f32,
        budget: u32,
    ) -> (Result<Walk, Lost>, Vec<u8>) {
        let (b, w, h) = setup(rows);
        let g = Grid::new(w, h, &b).unwrap();
        let mut tau_buf = vec![[1.0f32; 4]; g.cells()];
        let tau = Table::new(Blocks::new(w, h), &mut tau_buf);
        let heur = Heuristic::new(goal, Some(Attraction { a, xi: 1.0 }), 2.0);
        let moves = Moves::new(g, &[]);
        let dead = vec![0u32; bitmap::words(g.cells())];
        let c = Ant {
            moves: &moves,
            start,
            goal,
            tau: &tau,
            heuristic: &heur,
            alpha: 1.0,
            dead_end,
            dead: &dead,
            route: None,
            weights: None,
            budget,
        };
        let mut tabu = vec![0u32; bitmap::words(g.cells())];
        let mut tour = vec![0u8; g.cells()];
        let mut rng = Xoshiro128pp::from_u64(seed);
        let walk = c.walk(&mut rng, &mut TabuSet::new(&mut tabu), &mut tour);
        (walk, tour)
    }

    /// Walk the ant in pieces of `piece` moves by one loop (`cells`: [`Ant::walk_cells`], or
    /// [`Ant::walk_table`] for an ant with a weight table; else the general one), with the tabu
    /// set in the rows layout where `rows` and the map is narrow enough (over junk words, a set
    /// made again at each piece as the planner's colony does): every piece's result, the tour,
    /// the tabu set (its cells, in the linear layout) and the generator's state at the end.
    #[allow(clippy::type_complexity)]
    fn pieces(
        ant: &Ant<'_, '_, '_>,
        cells: bool,
        rows: bool,
        seed: u64,
        piece: u32,
        tour_len: usize,
    ) -> (
        Vec<Result<Option<Walk>, Lost>>,
        Vec<u8>,
        Vec<u32>,
        Xoshiro128pp,
    ) {
        let grid = ant.moves.grid();
        let cells_n = grid.cells();
        let (w, h) = (usize::from(grid.width()), usize::from(grid.height()));
        let mut tabu = vec![0u32; bitmap::words(cells_n)];
        let mut spare: Vec<u32> = (0..crate::colony::tabu::rows_words(cells_n) as u32)
            .map(|i| i.wrapping_mul(0x9E37_79B9))
            .collect();
        let mut tour = vec![0u8; tour_len];
        let mut rng = Xoshiro128pp::from_u64(seed);
        let mut trail = None;
        let mut out = Vec::new();
        let linear = loop {
            let mut set = TabuSet::new(&mut tabu);
            if rows {
                set = set.with_rows(&mut spare, w, h, ant.dead);
                assert_eq!(set.is_rows(), w <= crate::colony::tabu::ROWS_WIDTH);
            }
            let trail = trail.get_or_insert_with(|| ant.begin(&mut set, &mut tour));
            let mut left = piece;
            let r = if cells && ant.weights.is_some() {
                // The loop reading the table (an entry a cell, no route: `resume` takes it).
                ant.resume(trail, &mut rng, &mut set, &mut tour, &mut left)
            } else {
                ant.resume_by(cells, trail, &mut rng, &mut set, &mut tour, &mut left)
            };
            out.push(r);
            if !matches!(r, Ok(None)) {
                let mut linear = vec![0u32; bitmap::words(cells_n)];
                for i in (0..cells_n).filter(|&i| set.contains(i)) {
                    bitmap::set(&mut linear, i);
                }
                break linear;
            }
        };
        (out, tour, linear, rng)
    }

    #[test]
    fn the_loop_for_an_entry_a_cell_walks_as_the_general_one() {
        // Random maps, pruning marks, pheromone (zeros and huge values included, so that every
        // weight can underflow or the sum overflow: the uniform draw), exponents, dead-end rules,
        // budgets, tour lengths and pieces: the same results, tours, tabu sets and generators.
        let mut r = Xoshiro128pp::from_u64(36);
        let taus = [0.0f32, 1e-30, 0.01, 0.5, 1.0, 3.0, 1e30, f32::MAX];
        let mut compared = (0, 0, 0, 0);
        for case in 0..400u64 {
            let (w, h) = (
                3 + (r.next_word() % 14) as u16,
                3 + (r.next_word() % 12) as u16,
            );
            let bits = crate::testutil::random_bits(&mut r, w, h, 0.3);
            let g = Grid::new(w, h, &bits).unwrap();
            let free: Vec<usize> = (0..g.cells()).filter(|&i| !g.blocked_at(i)).collect();
            if free.len() < 2 {
                continue;
            }
            let pick = |r: &mut Xoshiro128pp| free[r.next_word() as usize % free.len()];
            let (si, gi) = (pick(&mut r), pick(&mut r));
            let at =
                |i: usize| Point::new((i % usize::from(w)) as u16, (i / usize::from(w)) as u16);
            let (start, goal) = (at(si), at(gi));
            let mut tau_buf = vec![[1.0f32; 4]; g.cells()];
            let spread = r.next_word() % 3;
            for e in tau_buf.iter_mut().flatten() {
                *e = match spread {
                    0 => 0.1 + r.next_unit() * 5.0,
                    1 => taus[r.next_word() as usize % taus.len()],
                    _ => 1.0,
                };
            }
            let blocks = Blocks::new(w, h);
            assert_eq!(blocks.shift(), 0);
            let tau = Table::new(blocks, &mut tau_buf);
            let a = [0.05, 0.5, 1.0][r.next_word() as usize % 3];
            let beta = [0.0, 0.5, 2.0, 7.0][r.next_word() as usize % 4];
            let heur = Heuristic::new(goal, Some(Attraction { a, xi: 1.0 }), beta);
            let mut table = vec![0u8; g.cells()];
            assert!(Moves::fill(&g, &mut table));
            let moves = if case % 2 == 0 {
                Moves::new(g, &table)
            } else {
                Moves::new(g, &[])
            };
            let mut dead = vec![0u32; bitmap::words(g.cells())];
            if case % 3 == 0 {
                for &i in &free {
                    if i != si && i != gi && r.next_word() % 8 == 0 {
                        bitmap::set(&mut dead, i);
                    }
                }
            }
            let ant = Ant {
                moves: &moves,
                start,
                goal,
                tau: &tau,
                heuristic: &heur,
                alpha: [1.0, 1.0, 0.7, 2.0][r.next_word() as usize % 4],
                dead_end: if case % 5 == 0 {
                    DeadEnd::Die
                } else {
                    DeadEnd::Backtrack
                },
                dead: if case % 7 == 0 { &[] } else { &dead },
                route: None,
                weights: None,
                budget: if case % 4 == 0 {
                    r.next_word() % 60
                } else {
                    u32::MAX
                },
            };
            let tour_len = if case % 6 == 0 {
                1 + r.next_word() as usize % 12
            } else {
                g.cells()
            };
            let piece = [u32::MAX, 1, 3, 17][r.next_word() as usize % 4];
            let seed = u64::from(r.next_word());
            let cells = pieces(&ant, true, false, seed, piece, tour_len);
            let general = pieces(&ant, false, false, seed, piece, tour_len);
            assert_eq!(cells.0, general.0, "case {case}");
            assert_eq!(cells.1, general.1, "case {case}: tour");
            assert_eq!(cells.2, general.2, "case {case}: tabu");
            assert_eq!(cells.3, general.3, "case {case}: generator");
            // A set in the rows layout and no table: the loop for an entry a cell walks it in
            // that layout, the same walk.
            let by_rows = pieces(&ant, true, true, seed, piece, tour_len);
            assert_eq!(by_rows, general, "case {case}: rows without a table");
            // The same loop reading a weight table (its words junk until cleared, small numbers
            // that an open-move mask may equal): three ants of one iteration, so that rows and
            // sums another ant filled are read, walk as the general loop; the first two with
            // the tabu set in the rows layout, the third in the linear one.
            let n = crate::colony::weights::words(g.cells());
            let mut words: Vec<u32> = (0..n as u32).map(|i| i.wrapping_mul(37) % 256).collect();
            let t = WeightTable::of(&mut words, g.cells()).unwrap();
            t.clear();
            let tabled = Ant {
                weights: Some(&t),
                ..ant
            };
            for (k, seed) in [seed, seed ^ 0x5A5A, seed.wrapping_add(7)]
                .into_iter()
                .enumerate()
            {
                let table = pieces(&tabled, true, k < 2, seed, piece, tour_len);
                let general = pieces(&ant, false, false, seed, piece, tour_len);
                assert_eq!(table.0, general.0, "case {case}, ant {k}: table");
                assert_eq!(table.1, general.1, "case {case}, ant {k}: table's tour");
                assert_eq!(table.2, general.2, "case {case}, ant {k}: table's tabu");
                assert_eq!(
                    table.3, general.3,
                    "case {case}, ant {k}: table's generator"
                );
            }
            compared.3 += (0..g.cells()).filter(|&i| t.is_filled(i)).count();
            match cells.0.last() {
                Some(Ok(Some(_))) => compared.0 += 1,
                Some(Err(_)) => compared.1 += 1,
                _ => {}
            }
            compared.2 += cells.0.len();
        }
        // Both kinds of ending, and walks cut into pieces, were compared; the tables' rows
        // were filled and read.
        assert!(
            compared.0 > 100 && compared.1 > 20 && compared.3 > 1000,
            "{compared:?}"
        );
    }

    #[test]
    fn a_walk_over_its_move_budget_is_abandoned_and_one_within_it_is_unchanged() {
        // The pull of the goal leads into the pocket first: the walk needs backtracking moves.
        let rows = [
            "......", //
            ".####.", //
            ".#..#.", //
            ".#..#.", //
            ".#....", //
        ];
        let ends = (Point::new(2, 2), Point::new(0, 0));
        let mut abandoned = 0;
        for seed in 0..50 {
            let (free, tour) = walk_on(&rows, ends, DeadEnd::Backtrack, seed, 0.05, u32::MAX);
            let free = free.unwrap();
            // Exactly enough: the same walk, the same tour.
            let (exact, again) = walk_on(&rows, ends, DeadEnd::Backtrack, seed, 0.05, free.moves);
            assert_eq!(exact, Ok(free));
            assert_eq!(again[..free.steps], tour[..free.steps]);
            // One move short: abandoned, whatever the seed.
            let (short, _) = walk_on(&rows, ends, DeadEnd::Backtrack, seed, 0.05, free.moves - 1);
            assert_eq!(short, Err(Lost::Budget));
            abandoned += usize::from(free.moves > free.steps as u32);
        }
        // The pocket made some walks back out of it: the budget had backtracking to cut.
        assert!(abandoned > 0);
    }

    #[test]
    fn backtracking_escapes_a_trap() {
        // The greedy direction leads into a pocket; the ant must back out.
        let rows = [
            "......", //
            ".####.", //
            ".#..#.", //
            ".#..#.", //
            ".#....", //
        ];
        for seed in 0..50 {
            let (w, tour) = run(
                &rows,
                Point::new(2, 2),
                Point::new(0, 0),
                DeadEnd::Backtrack,
                seed,
            )
            .unwrap();
            // Replay the tour: it must end at the goal.
            let (b, wd, h) = setup(&rows);
            let g = Grid::new(wd, h, &b).unwrap();
            let mut p = Point::new(2, 2);
            for d in &tour {
                p = g.step(p, *d).unwrap();
            }
            assert_eq!(p, Point::new(0, 0));
            assert_eq!(w.straight + w.diagonal, tour.len() as u32);
        }
    }

    #[test]
    fn dying_ants_die_in_dead_ends() {
        // The start sits in a corridor between the goal (west) and a dead end (east). Without
        // goal attraction (a = 1) both first moves weigh the same, so about half the ants walk
        // east into the dead end, where a dying ant dies.
        let rows = [
            "#######", //
            "G..S...", //
            "#######", //
        ];
        let (start, goal) = (Point::new(3, 1), Point::new(0, 1));
        let mut died = 0;
        let mut reached = 0;
        for seed in 0..200 {
            match run_with(&rows, start, goal, DeadEnd::Die, seed, 1.0) {
                Some((w, tour)) => {
                    reached += 1;
                    // An ant that arrived never turned back: three steps west.
                    assert_eq!(tour, [4, 4, 4]);
                    assert_eq!(w.moves, 3);
                }
                None => died += 1,
            }
        }
        assert_eq!(died + reached, 200);
        // 200 fair coin flips: 100 +- 3.5 standard deviations.
        assert!((65..=135).contains(&died), "{died} of 200 died");
        // Backtracking never loses one: the ants that went east come back.
        let mut turned_back = 0;
        for seed in 0..200 {
            let (w, tour) = run_with(&rows, start, goal, DeadEnd::Backtrack, seed, 1.0).unwrap();
            assert_eq!(tour, [4, 4, 4]);
            // East and back: 3 forward, 3 back (the dead end counts as a move), then 3 west.
            if w.moves > 3 {
                turned_back += 1;
            }
        }
        assert_eq!(
            turned_back, died,
            "the same seeds walk east with either rule"
        );
    }

    #[test]
    fn roulette_picks_in_proportion_to_the_weights() {
        // Chi-square goodness of fit of 200 000 draws with a fixed seed, for weight sets with
        // small, equal and zero entries (a zero weight must never be picked).
        let sets: [&[f32]; 4] = [
            &[1.0, 2.0, 3.0, 4.0],
            &[0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5],
            &[400.0, 1.0, 0.0, 2395.0, 20.0],
            &[1e-3, 1.0],
        ];
        // 99.9 % quantiles of chi-square with k - 1 degrees of freedom, k = 2..=8.
        let crit = [0.0, 0.0, 10.83, 13.82, 16.27, 18.47, 20.52, 22.46, 24.32];
        let draws = 200_000u32;
        for (seed, w) in sets.iter().enumerate() {
            let mut rng = Xoshiro128pp::from_u64(seed as u64 + 11);
            let total: f32 = w.iter().sum();
            let mut count = [0u32; 8];
            for _ in 0..draws {
                count[roulette(&mut rng, w, total)] += 1;
            }
            let mut chi2 = 0.0f64;
            let mut k = 0;
            for (i, &wi) in w.iter().enumerate() {
                let want = f64::from(draws) * f64::from(wi) / f64::from(total);
                if wi == 0.0 {
                    assert_eq!(count[i], 0, "{w:?}: a zero weight was picked");
                    continue;
                }
                k += 1;
                chi2 += (f64::from(count[i]) - want).powi(2) / want;
            }
            assert!(
                chi2 < crit[k],
                "{w:?}: chi2 {chi2:.2} ({:?})",
                &count[..w.len()]
            );
        }
        // Every weight underflowed: uniform.
        let mut rng = Xoshiro128pp::from_u64(5);
        let mut count = [0u32; 3];
        for _ in 0..30_000 {
            count[roulette(&mut rng, &[0.0; 3], 0.0)] += 1;
        }
        let chi2: f64 = count
            .iter()
            .map(|&c| (f64::from(c) - 10_000.0).powi(2) / 10_000.0)
            .sum();
        assert!(chi2 < crit[3], "uniform fallback: {count:?}");
    }
}
