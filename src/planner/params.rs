//! The planner's parameters: which variant runs ([`Algorithm`]) and every tunable ([`Params`]),
//! with their valid ranges ([`Params::validate`]).

use crate::colony::ant::DeadEnd;
use crate::colony::heuristic::Attraction;
use crate::error::{Error, Param};
use crate::named::named;
use crate::polish::smoothing::SmoothingKind;

/// The four variants the paper compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "lowercase")
)]
pub enum Algorithm {
    /// Plain ant colony: `eta = 1 / d_ij`, classic ant-system update.
    Aca,
    /// ACA plus the potential field's goal attraction in `eta`.
    Paca,
    /// PACA plus the wolves-distribution pheromone update.
    Haca,
    /// HACA plus line-of-sight smoothing of the result.
    #[default]
    Ohaca,
}

named!(
    Algorithm,
    "All four, in the paper's order.",
    [Aca => "aca", Paca => "paca", Haca => "haca", Ohaca => "ohaca"]
);

impl Algorithm {
    /// Uses the goal attraction in the heuristic.
    pub const fn attracts(self) -> bool {
        !matches!(self, Algorithm::Aca)
    }

    /// Uses the wolves-distribution update.
    pub const fn wolves(self) -> bool {
        matches!(self, Algorithm::Haca | Algorithm::Ohaca)
    }
}

/// Every tunable of the planner.
///
/// Two presets: [`Params::default`] is this project's setting (the paper's `alpha`, `beta`, `rho`,
/// `Q`, `a`, `xi` and `N`, 12 ants instead of the paper's `M = 50`, plus backtracking ants, path
/// tightening, dead-end pruning, early stopping after 10 stale iterations (1 with the local
/// search and for a warm replan), the local search and shortest smoothing); [`Params::paper`] is
/// the paper's algorithm as written (50 ants that die at dead ends, no tightening, no pruning,
/// always all `N` iterations, no local search, greedy smoothing).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Params {
    /// Which variant to run.
    pub algorithm: Algorithm,
    /// Ants per iteration (paper: M = 50; default 12, see [`Params::DEFAULT`]).
    pub ants: u16,
    /// Maximum iterations (paper: N = 100).
    pub iterations: u16,
    /// Pheromone exponent (paper: 1).
    pub alpha: f32,
    /// Heuristic exponent (paper: 2).
    pub beta: f32,
    /// Evaporation rate, in `(0, 1]` (paper: 0.1).
    pub rho: f32,
    /// Pheromone deposit constant (paper: 1).
    pub q: f32,
    /// Goal-attraction base `a`, in `(0, 1]` (paper: 0.05).
    pub a: f32,
    /// Potential-field gain `xi` (paper: 1).
    pub xi: f32,
    /// Initial pheromone on every edge.
    pub tau0: f32,
    /// Lower pheromone bound (the paper's `delta = 0.01`).
    pub tau_min: f32,
    /// Upper pheromone bound.
    pub tau_max: f32,
    /// Stop when the best path has not improved for this many iterations; 0 = never stop early.
    pub patience: u16,
    /// [`Params::patience`] for a warm start ([`crate::planner::Run::warm`]), whose colony
    /// already holds the previous plan's trail; 0 = the same as `patience`.
    pub warm_patience: u16,
    /// [`Params::patience`] for a run that refines its result ([`Params::refine`]):
    /// the local search straightens the path, so the colony only has to find the corridor;
    /// 0 = the same as `patience`. A warm start's `warm_patience` comes first. In a run that
    /// refines, a new best counts as a gain only if it is more than 1 % shorter than the best at
    /// the last gain ([`crate::planner::REFINE_GAIN`]); a smaller one is kept but the iteration
    /// counts as stale. On a large map such a run also stops, whatever its patience, after an
    /// iteration whose ants settled the corridor ([`crate::planner::settled`]).
    pub refine_patience: u16,
    /// Seed of the random generator.
    pub seed: u64,
    /// What an ant does at a dead end.
    pub dead_end: DeadEnd,
    /// How OHACA smooths the result (the other variants never smooth).
    pub smoothing: SmoothingKind,
    /// Straighten each ant's path before the pheromone update ([`crate::colony::tighten::tighten`]); not in
    /// the paper, off for faithful comparisons.
    pub tighten: bool,
    /// Prune the cells no shortest path needs before the ants run ([`crate::map::prune`]); not in the
    /// paper, off for faithful comparisons.
    pub prune: bool,
    /// OHACA replaces each piece of the best raw path by the exact shortest path inside a window
    /// around it before smoothing ([`crate::polish::refine`]; on maps of at most
    /// [`crate::colony::pheromone::BLOCKS`] cells the window is the whole map, so the raw path is the
    /// optimum); not in the paper, off for faithful comparisons. A workspace that cannot lend the
    /// scratch keeps the colony's path.
    pub refine: bool,
}

impl Default for Params {
    fn default() -> Self {
        Params::DEFAULT
    }
}

impl Params {
    /// This project's setting ([`Params::default`]), as a constant.
    ///
    /// 12 ants an iteration where the paper has 50: with the local search (`refine`) the colony
    /// only has to choose the corridor, and the exact search in windows along its best path makes
    /// the path inside it. Measured on the 20 large Moving AI maps (10 longest scenarios, seeds
    /// 1-2; `BENCHMARKS.md` 1b), the mean raw length over the optimum is 1.0009 with 50 ants,
    /// 1.0009 with 20, 1.0008 with 12 and 1.0009 with 8 (whose worst plan, 1.0123 on Sydney, is
    /// worse than 50's 1.0088); the shared small maps are the same with 8, 12 and 50. The ants
    /// are most of a plan's instructions, so 12 costs about a quarter of 50's colony (issue 27).
    /// The paper preset keeps its 50.
    pub const DEFAULT: Params = Params {
        algorithm: Algorithm::Ohaca,
        ants: 12,
        iterations: 100,
        alpha: 1.0,
        beta: 2.0,
        rho: 0.1,
        q: 1.0,
        a: 0.05,
        xi: 1.0,
        tau0: 1.0,
        tau_min: 0.01,
        tau_max: 100.0,
        patience: 10,
        warm_patience: 1,
        refine_patience: 1,
        seed: 1,
        dead_end: DeadEnd::Backtrack,
        smoothing: SmoothingKind::Shortest,
        tighten: true,
        prune: true,
        refine: true,
    };

    /// The paper's setting as written: `alpha = 1`, `beta = 2`, `rho = 0.1`, `Q = 1`, `a = 0.05`,
    /// `xi = 1`, `M = 50` ants (the default has 12), always the full `N = 100` iterations (`patience = 0`), ants that
    /// die at dead ends, no path tightening, no dead-end pruning, no local search and the paper's
    /// greedy smoothing (section 4.3). The constants, the pheromone bounds and the seed are [`Params::default`]'s
    /// (the paper gives `delta = 0.01` and no initial value). Use it for faithful comparisons;
    /// `docs/ALGORITHM.md` lists where the default differs and why.
    pub const fn paper() -> Self {
        Params {
            ants: 50,
            patience: 0,
            warm_patience: 0,
            refine_patience: 0,
            dead_end: DeadEnd::Die,
            smoothing: SmoothingKind::Greedy,
            tighten: false,
            prune: false,
            refine: false,
            ..Params::DEFAULT
        }
    }

    /// The goal attraction of the heuristic: `a` and `xi` for the variants that attract
    /// ([`Algorithm::attracts`]), `None` for plain ACA.
    pub const fn attraction(&self) -> Option<Attraction> {
        if self.algorithm.attracts() {
            Some(Attraction {
                a: self.a,
                xi: self.xi,
            })
        } else {
            None
        }
    }

    /// Check every field's range.
    pub fn validate(&self) -> Result<(), Error> {
        let bad = |p| Err(Error::BadParam(p));
        let in_range = |v: f32, lo: f32, hi: f32| v.is_finite() && v >= lo && v <= hi;
        if self.ants == 0 {
            return bad(Param::Ants);
        }
        if self.iterations == 0 {
            return bad(Param::Iterations);
        }
        if !in_range(self.alpha, 0.0, 16.0) {
            return bad(Param::Alpha);
        }
        if !in_range(self.beta, 0.0, 16.0) {
            return bad(Param::Beta);
        }
        if !(self.rho > 0.0 && self.rho <= 1.0) {
            return bad(Param::Rho);
        }
        if !(self.q.is_finite() && self.q > 0.0) {
            return bad(Param::Q);
        }
        if !(self.a > 0.0 && self.a <= 1.0) {
            return bad(Param::A);
        }
        if !(self.xi.is_finite() && self.xi >= 0.0) {
            return bad(Param::Xi);
        }
        let t_ok = self.tau_min.is_finite()
            && self.tau_max.is_finite()
            && self.tau0.is_finite()
            && self.tau_min > 0.0
            && self.tau_min <= self.tau0
            && self.tau0 <= self.tau_max;
        if !t_ok {
            return bad(Param::Tau);
        }
        Ok(())
    }
}
