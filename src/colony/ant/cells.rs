//! The walk loop for maps whose pheromone has an entry a cell and no route ([`Ant::walk_cells`]):
//! the general loop's moves and draws ([`Ant::walk_general`](super::Ant)), bit for bit, at fewer
//! instructions a move. What it owns: that loop and its roulette over the open moves' bits. What
//! it guarantees: the same results, tours, tabu sets and generator states as the general loop
//! (`the_loop_for_an_entry_a_cell_walks_as_the_general_one` in the parent's tests), and no panic
//! (every read is checked, the lints deny indexing).

use super::*;
use crate::colony::weights::{self, WeightTable};

impl Ant<'_, '_, '_> {
    /// [`Ant::walk_general`] where the pheromone has an entry per cell (a map of at most
    /// [`crate::colony::pheromone::BLOCKS`] cells in the planner's workspaces: the block shift 0) and the potential field pulls toward the goal
    /// (no route): the same moves and draws, bit for bit, at fewer instructions a move. An edge's
    /// entry is `4 * cell` plus a slot offset fixed for the map ([`slot_offsets`]); the weights
    /// are kept by direction, so the roulette walks the open moves' bits again instead of a
    /// list of candidates. The same sums in the same order: the candidates are the set bits of
    /// the open mask, lowest first, as in the general loop.
    // Not inlined: the general loop's function stays as it was (its registers, its count of
    // instructions on the device).
    #[inline(never)]
    pub(super) fn walk_cells(
        &self,
        trail: &mut Trail,
        rng: &mut Xoshiro128pp,
        tabu: &mut TabuSet<'_>,
        tour: &mut [Dir],
        limit: &mut u32,
        pow: impl Fn(f32) -> f32,
    ) -> Result<Option<Walk>, Lost> {
        // The generator as a local: the loop keeps its state in registers (through `rng` it
        // would store it at every draw, since the tour and tabu writes might alias it).
        let mut gen = rng.clone();
        // The tabu set's layout, as in `walk_table` (only a host build has the rows layout: the
        // device's loop is the linear one alone).
        #[cfg(any(feature = "alloc", test))]
        if tabu.is_rows() {
            let r = self.cells_loop::<true>(None, trail, &mut gen, tabu, tour, limit, pow);
            *rng = gen;
            return r;
        }
        let r = self.cells_loop::<false>(None, trail, &mut gen, tabu, tour, limit, pow);
        *rng = gen;
        r
    }

    /// [`Ant::walk_cells`] reading the weights from the iteration's `table`
    /// ([`crate::colony::weights`]): a cell's row is filled, with the products the loop without
    /// a table computes at a move, when an ant first has a choice on it in the iteration; a move
    /// then sums the open moves' weights from the row, in the same order. So the same moves and
    /// draws, bit for bit, as [`Ant::walk_cells`] (a test compares them on random maps).
    #[cfg(any(feature = "alloc", test))]
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn walk_table(
        &self,
        table: &WeightTable<'_>,
        trail: &mut Trail,
        rng: &mut Xoshiro128pp,
        tabu: &mut TabuSet<'_>,
        tour: &mut [Dir],
        limit: &mut u32,
        pow: impl Fn(f32) -> f32,
    ) -> Result<Option<Walk>, Lost> {
        let mut gen = rng.clone();
        // The tabu set's layout, chosen when the set was made: the rows layout's reads where it
        // has it (a narrow map), else the linear layout's.
        let r = if tabu.is_rows() {
            self.cells_loop::<true>(Some(table), trail, &mut gen, tabu, tour, limit, pow)
        } else {
            self.cells_loop::<false>(Some(table), trail, &mut gen, tabu, tour, limit, pow)
        };
        *rng = gen;
        r
    }

    /// The loop of [`Ant::walk_cells`] (`table` `None`) and [`Ant::walk_table`], reading the
    /// tabu set in its rows layout (`ROWS`: by the ant's column and row, [`TabuSet::around_at`])
    /// or in its linear one (by the cell's index): the caller knows which the set has.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn cells_loop<const ROWS: bool>(
        &self,
        table: Option<&WeightTable<'_>>,
        trail: &mut Trail,
        rng: &mut Xoshiro128pp,
        tabu: &mut TabuSet<'_>,
        tour: &mut [Dir],
        limit: &mut u32,
        pow: impl Fn(f32) -> f32,
    ) -> Result<Option<Walk>, Lost> {
        let grid = self.moves.grid();
        // The offset of a step, computed where it is needed: a table of them would be one
        // more array on the stack, whose depth the device's RAM budget counts.
        let w_off = grid.width() as isize;
        let step = |d: usize| {
            let (dx, dy) = (
                DX.get(d & 7).copied().unwrap_or(0),
                DY.get(d & 7).copied().unwrap_or(0),
            );
            // |dy|, |dx| <= 1 and the width <= 65535: no overflow.
            (dy as isize).wrapping_mul(w_off).wrapping_add(dx as isize)
        };
        let slots = slot_offsets(&grid.offsets());
        let tau = self.tau.flat();
        let goal = grid.index(self.goal);
        let Trail {
            mut cur,
            mut ci,
            mut steps,
            mut moves,
            mut may_tighten,
            block,
            target,
        } = *trail;
        // By direction; only the open moves' entries are read, each written first in the same
        // step.
        let mut weight = [0.0f32; 8];
        let width = usize::from(grid.width());
        let first = moves;
        let stop = self.budget.min(moves.saturating_add(*limit));
        while ci != goal {
            let allowed = self.moves.at(ci, cur);
            let tabu_moves = visited::<ROWS>(tabu, ci, cur, width) & allowed;
            // As in the general loop.
            if !may_tighten && tabu_moves & tabu_moves.wrapping_sub(1) != 0 {
                may_tighten = self.shortcut_seen(ci, tabu_moves, step);
            }
            let open = allowed & !tabu_moves;
            moves = moves.saturating_add(1);
            if moves > stop {
                if moves > self.budget {
                    *limit = limit.saturating_sub(moves.wrapping_sub(first));
                    return Err(Lost::Budget);
                }
                // The piece is over: the next one makes this move (nothing above changed the
                // walk but `may_tighten`, which it sets again).
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
            let d = if open == 0 {
                match self.dead_end {
                    DeadEnd::Die => {
                        *limit = limit.saturating_sub(moves.wrapping_sub(first));
                        return Err(Lost::Died);
                    }
                    DeadEnd::Backtrack => {
                        // As in the general loop.
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
                        ci = ci.wrapping_add_signed(step(usize::from(back)));
                        cur = neighbour(cur, back);
                        continue;
                    }
                }
            } else if open & open.wrapping_sub(1) == 0 {
                // One open move: taken without a draw.
                open.trailing_zeros() as u8 & 7
            } else if let Some(row) = table.and_then(|t| {
                t.row(ci, || {
                    // Every direction's weight as the loop below computes an open move's
                    // (a closed move's is never read: its entry may be another edge's, or 0).
                    let eta = self.heuristic.row(cur);
                    let c4 = ci.wrapping_mul(4);
                    core::array::from_fn(|di| {
                        let ti = c4.wrapping_add_signed(slots.get(di).copied().unwrap_or(0));
                        pow(tau.get(ti).copied().unwrap_or(0.0)) * eta.get(di)
                    })
                })
            }) {
                // The same running sum, in the same order, as below (kept by the row for the
                // last mask it was asked for).
                let total = weights::total(row, open, || {
                    let mut total = 0.0f32;
                    let mut m = open;
                    while m != 0 {
                        let di = m.trailing_zeros() as usize & 7;
                        m &= m.wrapping_sub(1);
                        total += weights::weight(row, di);
                    }
                    total
                });
                roulette_open(rng, |di| weights::weight(row, di), open, total)
            } else {
                let eta = self.heuristic.row(cur);
                // `4 * ci` fits: the table holds 4 entries a cell.
                let c4 = ci.wrapping_mul(4);
                let mut total = 0.0f32;
                let mut m = open;
                while m != 0 {
                    let di = m.trailing_zeros() as usize & 7;
                    m &= m.wrapping_sub(1);
                    let ti = c4.wrapping_add_signed(slots.get(di).copied().unwrap_or(0));
                    let w = pow(tau.get(ti).copied().unwrap_or(0.0)) * eta.get(di);
                    if let Some(slot) = weight.get_mut(di) {
                        *slot = w;
                    }
                    total += w;
                }
                roulette_open(
                    rng,
                    |di| weight.get(di).copied().unwrap_or(0.0),
                    open,
                    total,
                )
            };
            let Some(slot) = tour.get_mut(steps) else {
                // As in the general loop: not a move.
                match self.dead_end {
                    DeadEnd::Die => {
                        *limit = limit.saturating_sub(moves.wrapping_sub(first));
                        return Err(Lost::Overflow);
                    }
                    DeadEnd::Backtrack => {
                        let ni = ci.wrapping_add_signed(step(usize::from(d)));
                        enter::<ROWS>(tabu, ni, neighbour(cur, d));
                        moves = moves.wrapping_sub(1); // counted above: at least 1
                        continue;
                    }
                }
            };
            *slot = d;
            steps = steps.wrapping_add(1); // < tour.len() + 1: the slot existed
            ci = ci.wrapping_add_signed(step(usize::from(d)));
            cur = neighbour(cur, d);
            enter::<ROWS>(tabu, ci, cur);
        }
        *limit = limit.saturating_sub(moves.wrapping_sub(first));
        self.arrived(tabu, tour, steps, moves, may_tighten)
    }
}

/// The tabu set's cells around cell `ci` at `at` on a map `width` wide, as a direction mask
/// ([`TabuSet::around`]), read in the rows layout (`ROWS`) or the linear one, unchecked.
#[inline(always)]
fn visited<const ROWS: bool>(tabu: &TabuSet<'_>, ci: usize, at: Point, width: usize) -> u8 {
    #[cfg(any(feature = "alloc", test))]
    if ROWS {
        return tabu.around_at(at);
    }
    let _ = at;
    tabu.around_linear(ci, width)
}

/// Put cell `ci` at `at` in the tabu set ([`TabuSet::insert`]), in the rows layout (`ROWS`) or
/// the linear one, unchecked.
#[inline(always)]
fn enter<const ROWS: bool>(tabu: &mut TabuSet<'_>, ci: usize, at: Point) {
    #[cfg(any(feature = "alloc", test))]
    if ROWS {
        return tabu.insert_at(at);
    }
    let _ = at;
    tabu.insert_linear(ci);
}

/// [`roulette`] over the open moves (the set bits of `open`, at least two, lowest first) with
/// their weights by direction from `weight`: the direction [`roulette`] picks from the list of
/// those moves' weights, with the same draw and the same running sums (so bit for bit the same
/// choice).
#[inline]
fn roulette_open(
    rng: &mut Xoshiro128pp,
    weight: impl Fn(usize) -> f32,
    open: u8,
    total: f32,
) -> Dir {
    if !(total > 0.0 && total <= f32::MAX) {
        // The draw here, the choice out of line: the generator's state never has its address
        // taken, so the walk keeps it in registers.
        return uniform_open(rng.next_word(), open);
    }
    let r = rng.next_unit() * total;
    let mut acc = 0.0f32;
    let mut m = open;
    let mut last = 0u8;
    while m != 0 {
        let di = m.trailing_zeros() as u8 & 7;
        m &= m.wrapping_sub(1);
        acc += weight(usize::from(di));
        if r < acc {
            return di;
        }
        last = di;
    }
    // Rounding can leave r just above the running sum: the last open move.
    last
}

/// [`roulette`]'s uniform choice among the open moves (every weight underflowed, or the sum
/// overflowed: rare, so out of the loop): the k-th of the set bits of `open`, from the draw
/// `word`.
#[cold]
#[inline(never)]
fn uniform_open(word: u32, open: u8) -> Dir {
    let n = u64::from(open.count_ones());
    let k = (u64::from(word).wrapping_mul(n) >> 32) as u32;
    let mut m = open;
    for _ in 0..k {
        m &= m.wrapping_sub(1);
    }
    m.trailing_zeros() as u8 & 7
}
