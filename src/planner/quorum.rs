//! The quorum: an iteration of a refining run on a large map ends after its first [`QUORUM`]
//! ants when they all arrived and agree on the corridor, instead of walking every ant.
//!
//! What it owns: the rule ([`reached`], asked by the colony after each ant) and its replay
//! from a recorded iteration ([`ended`], for the checks that read a plan's curve). What it
//! guarantees: an iteration the quorum ends is the run's last one (the run records it as
//! settled, [`crate::planner::settled`]), it walked exactly [`QUORUM`] ants, every one of them
//! arrived, and their mean length is within [`REFINE_GAIN`] of the iteration's best, computed
//! as the run records it (`sum / arrived`, then `mean * REFINE_GAIN <= best`), so the curve
//! replays the decision bit for bit. It applies where [`crate::planner::settled`] does (a run
//! with the local search on a map of more than [`crate::colony::pheromone::BLOCKS`] cells), so the
//! paper preset and the small maps never meet it.
//!
//! **Why.** With the local search the colony only chooses the corridor
//! ([`crate::planner::settled`]): where the route and the local search already settle it, the
//! iteration's ants walk the same corridor one after the other, and each costs about 1,000
//! instructions a cell on the device (a walk step, its tightening, its deposit). On Nav2's
//! depot the first iteration's twelve ants agree to within 1 % on every seed that settles; the
//! first four agreeing is the same decision taken at a third of the walks. Where the choice is
//! real (`ht_chantry`, `w_woundedcoast`: the ablation row of `BENCHMARKS.md`) the first ants
//! disagree and the iteration goes on as before. The decision is taken once, after exactly
//! [`QUORUM`] ants (not after every ant from then on, which would test the same hypothesis
//! eight times and stop on a chance agreement more often). Measured in `docs/ALGORITHM.md`
//! ("The quorum") and `docs/bench/lattice-issue36.md`.

use crate::planner::{CurvePoint, REFINE_GAIN};

/// The ants an iteration walks before the quorum may end it.
pub const QUORUM: u16 = 4;

/// Whether the iteration may end now: `walked` ants (of `ants`) walked, `arrived` of them
/// arrived with lengths summing to `sum`, the shortest `best`. True only right after the
/// [`QUORUM`]-th ant of an iteration of more than [`QUORUM`] ants, when every one of them
/// arrived and their mean is within [`REFINE_GAIN`] of `best`.
pub fn reached(walked: u16, ants: u16, arrived: u32, sum: f32, best: f32) -> bool {
    walked == QUORUM && QUORUM < ants && arrived == u32::from(walked) && agree(sum, arrived, best)
}

/// Whether a recorded iteration was ended by the quorum ([`reached`] replayed from the curve).
pub fn ended(point: &CurvePoint, ants: u16) -> bool {
    point.walked == QUORUM
        && QUORUM < ants
        && point.arrived == point.walked
        && point.mean * REFINE_GAIN <= point.best
}

/// The mean of `arrived` lengths summing to `sum` within [`REFINE_GAIN`] of `best`, as the run
/// records it (`CurvePoint::mean`).
fn agree(sum: f32, arrived: u32, best: f32) -> bool {
    arrived > 0 && (sum / arrived as f32) * REFINE_GAIN <= best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_quorum_is_reached_only_after_exactly_quorum_ants_that_all_arrived_and_agree() {
        let best = 100.0;
        let q = u32::from(QUORUM);
        let agreeing = f32::from(QUORUM) * 100.5;
        assert!(reached(QUORUM, 12, q, agreeing, best));
        // Not before, not after.
        assert!(!reached(QUORUM - 1, 12, q - 1, agreeing - 100.5, best));
        assert!(!reached(QUORUM + 1, 12, q + 1, agreeing + 100.5, best));
        // Not when an ant was lost, nor when they disagree by more than REFINE_GAIN.
        assert!(!reached(QUORUM, 12, q - 1, agreeing - 100.5, best));
        assert!(!reached(QUORUM, 12, q, f32::from(QUORUM) * 102.0, best));
        // Not in an iteration of QUORUM ants or fewer (it ends anyway).
        assert!(!reached(QUORUM, QUORUM, q, agreeing, best));
    }

    #[test]
    fn a_recorded_iteration_replays_the_decision() {
        let point = |walked, arrived, mean| CurvePoint {
            best: 100.0,
            mean,
            best_so_far: 100.0,
            arrived,
            walked,
        };
        assert!(ended(&point(QUORUM, QUORUM, 100.5), 12));
        assert!(!ended(&point(12, 12, 100.5), 12));
        assert!(!ended(&point(QUORUM, QUORUM - 1, 100.5), 12));
        assert!(!ended(&point(QUORUM, QUORUM, 102.0), 12));
        // The same numbers as `reached`, bit for bit.
        for mean in [100.0f32, 100.9, 101.0101, 101.02, 101.5] {
            let sum = mean * f32::from(QUORUM);
            let recorded = sum / f32::from(QUORUM);
            assert_eq!(
                reached(QUORUM, 12, u32::from(QUORUM), sum, 100.0),
                ended(&point(QUORUM, QUORUM, recorded), 12),
                "{mean}"
            );
        }
    }

    /// Plans on random maps of more than `BLOCKS` cells, every ant's tour observed: each
    /// iteration whose first `QUORUM` ants all arrived and agree (replayed from their tours, as
    /// the colony sums them) walked exactly those ants and was the run's last; every other
    /// iteration walked every ant. Both kinds occur. Fails when the colony ignores the quorum
    /// (it walks all twelve) or ends an iteration without one.
    #[test]
    fn an_iteration_ends_after_its_first_ants_exactly_when_they_agree() {
        use crate::geometry::steps_length;
        use crate::heap::HeapStorage;
        use crate::map::dir::is_diagonal;
        use crate::map::grid::{Grid, Point};
        use crate::planner::{Params, Run};
        use alloc::vec::Vec;

        let p = Params::default();
        let (w, h) = (80u16, 60u16);
        let (mut ended_runs, mut full_iterations) = (0, 0);
        for seed in 1..=16u64 {
            let mut rng = crate::rng::Xoshiro128pp::from_u64(seed);
            let density = [0.05, 0.15, 0.25, 0.3][(seed % 4) as usize];
            let mut bits = crate::testutil::random_bits(&mut rng, w, h, density);
            for i in [0usize, usize::from(w) * usize::from(h) - 1] {
                bits[i / 8] &= !(1 << (i % 8));
            }
            let g = Grid::new(w, h, &bits).unwrap();
            let params = Params { seed, ..p };
            let mut st = HeapStorage::for_run(g.cells(), &params).unwrap();
            let (s, goal) = (Point::new(0, 0), Point::new(w - 1, h - 1));
            let Ok(mut run) = Run::new(&g, s, goal, &params, st.workspace()) else {
                continue;
            };
            let mut tours: Vec<Vec<f32>> = Vec::new();
            loop {
                let mut lengths = Vec::new();
                let more = run.step_observed(|t| {
                    let d = t.iter().filter(|&&d| is_diagonal(d)).count() as u32;
                    lengths.push(steps_length(t.len() as u32 - d, d));
                });
                tours.push(lengths);
                if !more {
                    break;
                }
            }
            let Ok(plan) = run.finish() else { continue };
            let curve = plan.curve();
            assert_eq!(curve.len(), tours.len());
            for (i, (c, t)) in curve.iter().zip(&tours).enumerate() {
                let q = usize::from(QUORUM);
                let first_agree = t.len() >= q && {
                    let (mut sum, mut best) = (0.0f32, f32::INFINITY);
                    for &l in &t[..q] {
                        sum += l;
                        best = best.min(l);
                    }
                    agree(sum, QUORUM.into(), best)
                };
                // `tours` holds the arrived ants' tours in order: the first `QUORUM` ants' when
                // every ant walked arrived.
                let all_arrived = c.arrived == c.walked && usize::from(c.arrived) == t.len();
                if c.walked == QUORUM {
                    assert!(
                        all_arrived && first_agree,
                        "seed {seed} iteration {i}: {c:?}"
                    );
                    assert_eq!(i + 1, curve.len(), "seed {seed}: the quorum ends the run");
                    ended_runs += 1;
                } else {
                    assert_eq!(c.walked, params.ants, "seed {seed} iteration {i}: {c:?}");
                    assert!(
                        !(all_arrived && first_agree),
                        "seed {seed} iteration {i}: the first ants agreed, yet all walked"
                    );
                    full_iterations += 1;
                }
            }
        }
        assert!(
            ended_runs > 0 && full_iterations > 0,
            "{ended_runs} ended by the quorum, {full_iterations} full"
        );
    }
}
