//! Line-of-sight smoothing of the raw ant path (paper section 4.3): drop waypoints that a
//! straight, collision-free segment makes needless.
//!
//! Segments are checked with [`crate::geometry::segment_clear`] (the closed-square rule), so the
//! smoothed path never touches an obstacle, not even at a corner.
//!
//! Three kinds:
//!
//! - [`SmoothingKind::Shortest`] (default for OHACA): the shortest path that visits a subsequence
//!   of the raw path's cells, found by dynamic programming over the pairs that see each other and
//!   lie at most [`LOOKBACK`] raw cells apart (segment tests pruned by length). This is the
//!   reading that works: on the shared maps it lands on average within 1% of the any-angle optimum
//!   through cell centres, where the paper's greedy rule is up to 5% above it, because greedy
//!   keeps the first cell it cannot see past rather than the best one. Paths of at most
//!   `LOOKBACK + 1` cells (every shared small-map path) get the exact all-pairs DP, bit for bit as
//!   before the look-back existed. Longer paths get the windowed DP and then one greedy
//!   line-of-sight pass over its waypoints (a waypoint goes when its neighbours see each other),
//!   so a long straight stretch still ends up as one segment. See [`LOOKBACK`] for the cost. The
//!   planner's paths, locally shortest after its local search, take a bounded candidate scan
//!   ([`Smoother::bounded`]): at most `LOOKBACK / STRIDE + CHAIN + 2 NEAR` = 48 segment tests a
//!   raw cell, whatever the map.
//! - [`SmoothingKind::Greedy`]: the paper's steps 1-5 literally: from the anchor `S`, extend `N`
//!   along the path while `S` sees `N`; when it does not, the node before `N` becomes the next
//!   anchor and a waypoint. Kept for faithful comparisons.
//! - [`SmoothingKind::None`]: no smoothing; the waypoints are the raw path's corners (used by ACA,
//!   PACA and HACA, which the paper reports without post-processing).
//!
//! All three work in place on the caller's buffers and keep collinear points out of the output.

pub use crate::geometry::drop_collinear;
use crate::geometry::{distance, drop_middles, segment_clear};
use crate::map::grid::{Grid, Point};
use crate::named::named;
use crate::polish::links::PathLinks;
use crate::polish::taut::{segment_units, Pass};

/// How to post-process the raw path.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "lowercase")
)]
pub enum SmoothingKind {
    /// Keep the raw path; waypoints are its corners.
    None,
    /// The paper's greedy line-of-sight rule.
    Greedy,
    /// Shortest subsequence path (dynamic programming). Default.
    #[default]
    Shortest,
}

named!(
    SmoothingKind,
    "All three, default first.",
    [Shortest => "shortest", Greedy => "greedy", None => "none"]
);

/// How many raw cells back the [`SmoothingKind::Shortest`] DP looks for a cell that sees the
/// current one (`K`).
///
/// Cost: per raw cell `K - 1` candidate lengths (a square root each) and at most `K - 1`
/// candidate segments, each tested only when it is shorter than the best clear one so far, at
/// about `|dx| + |dy| <= 2K` cells per test: `O(n K^2)` cell tests at worst. On open maps most
/// candidates fail the length test; in mazes most pass it and are blocked (the colony's
/// 1,379-cell raw path on `maze-128-128-2` tests 117 segments per cell, nearly all rejected by
/// the sampled points of [`segment_clear`]): about 25 M device instructions for that path. The all-pairs DP is `O(n^3)` cell
/// tests at worst and `O(n^2)` length tests always. Measured on the colony's raw paths of the 20
/// longest scenarios of each of the 20 large Moving AI maps (43 to 4,844 cells; `cargo run
/// --release -p ohaca-host-tests --target host-tuple --example refine_large -- --smooth 1`):
/// with `K = 128` the smoothed length is on average within 0.22 % of the all-pairs DP's on every
/// map (worst single path +1.7 %), `K = 64` loses up to 1.4 % on average and `K = 256` at most
/// 0.04 %; on the longest paths (2,300-4,800 cells) the all-pairs DP takes 1.6-2.6 s per path on
/// the host and `K = 128` 35-115 ms.
pub const LOOKBACK: usize = 128;

/// Scratch entries [`smooth`] needs for a path of `n` cells: `(dist, prev)` =
/// `(min(n, LOOKBACK + 1), n)`. `dist` is a ring over the look-back window; `prev` holds one link
/// per raw cell to recover the chosen cells.
pub const fn scratch_for(n: usize) -> (usize, usize) {
    let ring = if n <= LOOKBACK {
        n
    } else {
        LOOKBACK.wrapping_add(1)
    };
    (ring, n)
}

/// Smooth the path `pts[..n]` in place; returns the number of waypoints now in `pts`.
/// `dist` and `prev` are scratch of at least [`scratch_for`]`(n)` entries (only
/// [`SmoothingKind::Shortest`] uses them; if they are too short it falls back to
/// [`SmoothingKind::Greedy`]).
pub fn smooth(
    grid: &Grid<'_>,
    kind: SmoothingKind,
    pts: &mut [Point],
    n: usize,
    dist: &mut [f32],
    prev: &mut PathLinks<'_>,
) -> usize {
    Smoother::new(kind, n, dist, prev).finish(grid, pts, dist, prev)
}

/// [`smooth`] a stretch at a time, so that a firmware can yield inside a long smoothing: the
/// shortest-path DP advances a given number of raw cells per [`Smoother::resume`], and
/// [`Smoother::finish`] does what is left and compacts the waypoints. The result does not depend
/// on how the work was cut: it is [`smooth`]'s, bit for bit. The caller passes the same buffers to
/// every call.
#[derive(Clone, Copy, Debug)]
pub struct Smoother {
    kind: SmoothingKind,
    /// Cells of the raw path.
    n: usize,
    /// Next raw cell of the DP (`n` once it is complete).
    j: usize,
    /// Entries of the `dist` ring used.
    ring: usize,
    /// A path longer than the ring takes the bounded candidate scan ([`Smoother::bounded`]).
    bounded: bool,
    /// Where [`Smoother::finish_piece`] stands after the DP.
    tail: Tail,
}

/// The steps of [`SmoothingKind::Shortest`] after the DP, a budget at a time
/// ([`Smoother::finish_piece`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Tail {
    /// The trace of the DP's links is next.
    Trace,
    /// The greedy merge ([`merge`]) of the waypoints `pts[..k]` (a path longer than the ring):
    /// `pts[..out]` kept so far, `i` the next interior waypoint to try.
    Merge { k: usize, i: usize, out: usize },
    /// Passes of [`crate::polish::taut::pull`]: `passes` done, the current one where it stands.
    Pull { pass: Pass, passes: u8 },
}

/// Work units of the trace of the DP's links a raw cell (a link followed and a cell copied; the
/// units of [`segment_units`]).
const TRACE_CELLS: usize = 4;

impl Smoother {
    /// Prepare to smooth `pts[..n]` with `kind`. Falls back to [`SmoothingKind::Greedy`] when
    /// `dist` and `prev` are shorter than [`scratch_for`]`(n)`.
    pub fn new(kind: SmoothingKind, n: usize, dist: &mut [f32], prev: &mut PathLinks<'_>) -> Self {
        let ring = n.min(LOOKBACK.wrapping_add(1));
        let kind = if kind == SmoothingKind::Shortest && (dist.len() < ring || !prev.holds(n)) {
            SmoothingKind::Greedy
        } else {
            kind
        };
        if let (Some(d0), false) = (dist.first_mut(), prev.is_empty()) {
            *d0 = 0.0;
            prev.link(0, 0);
        }
        Smoother {
            kind,
            n,
            j: if kind == SmoothingKind::Shortest && n >= 3 {
                1
            } else {
                n
            },
            ring,
            bounded: false,
            tail: Tail::Trace,
        }
    }

    /// The same smoothing with the bounded candidate scan ([`chain_cells`]) on a path longer than
    /// [`LOOKBACK`]` + 1` cells: at most `LOOKBACK / STRIDE + CHAIN + 2 NEAR` segment tests a raw
    /// cell instead of up to `LOOKBACK - 1`. For paths that are already locally shortest, as the
    /// planner's are after its local search ([`crate::polish::refine`]): there the result is within about
    /// 0.1 % of the full scan's (`docs/ALGORITHM.md`, "Smoothing"); on a wandering path that
    /// loops back on itself the full scan can find a much shorter way through its cells.
    pub fn bounded(self) -> Self {
        Smoother {
            bounded: true,
            ..self
        }
    }

    /// The rule it smooths with: the one asked for, or the greedy rule when its scratch was
    /// short ([`Smoother::new`]).
    pub fn kind(&self) -> SmoothingKind {
        self.kind
    }

    /// Cells of the raw path it smooths.
    pub fn cells(&self) -> usize {
        self.n
    }

    /// Advance the DP by at most `cells` raw cells; returns `true` while some remain.
    pub fn resume(
        &mut self,
        grid: &Grid<'_>,
        pts: &[Point],
        dist: &mut [f32],
        prev: &mut PathLinks<'_>,
        cells: usize,
    ) -> bool {
        let n = self.n.min(pts.len());
        let to = self.j.saturating_add(cells).min(n);
        let ring = dist.get_mut(..self.ring).unwrap_or_default();
        if self.bounded && self.ring < n {
            // A path longer than the look-back: the bounded scan along the chain of waypoints.
            let clear = |a: Point, b: Point| segment_clear(grid, a, b);
            chain_cells(clear, pts, ring, prev, BOUNDED_LOOKBACK, self.j..to);
        } else {
            dp_cells(grid, pts, ring, prev, LOOKBACK, self.j..to);
        }
        self.j = to.max(self.j);
        self.j < n
    }

    /// [`Smoother::finish`] a piece at a time, once the DP is done ([`Smoother::resume`]
    /// returned `false`): the trace, the merge of a bounded scan and the passes of the taut pull,
    /// for at most about `budget` work units a call (the units of
    /// [`crate::polish::taut::segment_units`]; a call with a budget always does some work, and
    /// may overrun it by a waypoint's segment tests). `Some(k)` with the waypoint count once done
    /// (the pieces write what `finish` writes, however the work is cut), `None` while work
    /// remains. The other kinds finish in one piece.
    pub fn finish_piece(
        &mut self,
        grid: &Grid<'_>,
        pts: &mut [Point],
        dist: &mut [f32],
        prev: &mut PathLinks<'_>,
        budget: u32,
    ) -> Option<usize> {
        let n = self.n.min(pts.len());
        if n < 3 || self.kind != SmoothingKind::Shortest {
            return Some(self.finish(grid, pts, dist, prev));
        }
        let mut left = budget.max(1);
        loop {
            if left == 0 {
                return None;
            }
            match self.tail {
                Tail::Trace => {
                    while self.resume(grid, pts, dist, prev, usize::MAX) {}
                    let k = trace(pts, n, prev);
                    let cost = u32::try_from(n / TRACE_CELLS).unwrap_or(u32::MAX);
                    left = left.saturating_sub(cost);
                    self.tail = if self.ring < n {
                        Tail::Merge { k, i: 1, out: 1 }
                    } else {
                        Tail::Pull {
                            pass: Pass::new(drop_collinear(pts, k)),
                            passes: 0,
                        }
                    };
                }
                Tail::Merge { k, i, out } => {
                    let clear = |a: Point, c: Point| segment_clear(grid, a, c);
                    match merge_resume(clear, pts, k, (i, out), &mut left) {
                        Ok(k) => {
                            self.tail = Tail::Pull {
                                pass: Pass::new(drop_collinear(pts, k)),
                                passes: 0,
                            }
                        }
                        Err((i, out)) => {
                            self.tail = Tail::Merge { k, i, out };
                            return None;
                        }
                    }
                }
                Tail::Pull { mut pass, passes } => {
                    let Some((k, changed)) = pass.resume(grid, pts, &mut left) else {
                        self.tail = Tail::Pull { pass, passes };
                        return None;
                    };
                    let passes = passes.saturating_add(1);
                    if changed && passes < crate::polish::taut::MAX_PASSES {
                        self.tail = Tail::Pull {
                            pass: Pass::new(k),
                            passes,
                        };
                        continue;
                    }
                    // `taut::pull`'s end, then `finish`'s.
                    let k = drop_collinear(pts, k);
                    return Some(drop_collinear(pts, k));
                }
            }
        }
    }

    /// Finish the DP if needed and write the waypoints to the front of `pts`; returns how many.
    pub fn finish(
        mut self,
        grid: &Grid<'_>,
        pts: &mut [Point],
        dist: &mut [f32],
        prev: &mut PathLinks<'_>,
    ) -> usize {
        let n = self.n.min(pts.len());
        if n < 3 {
            return n;
        }
        let k = match self.kind {
            SmoothingKind::None => n,
            SmoothingKind::Greedy => greedy(grid, pts, n),
            SmoothingKind::Shortest => {
                while self.resume(grid, pts, dist, prev, usize::MAX) {}
                let k = trace(pts, n, prev);
                let k = if self.ring < n {
                    merge(grid, pts, k)
                } else {
                    k
                };
                // Off the raw path's cells: pulled taut over the centres around it (from the
                // waypoints without their collinear ones, so the pull starts from the DP's path
                // as `smooth` has always returned it).
                let k = drop_collinear(pts, k);
                crate::polish::taut::pull(grid, pts, k)
            }
        };
        drop_collinear(pts, k)
    }
}

/// The paper's greedy rule, in place.
fn greedy(grid: &Grid<'_>, pts: &mut [Point], n: usize) -> usize {
    // Bounds: 3 <= n <= pts.len() (see `smooth`) and anchor < i, out < i, i <= n, so no
    // `wrapping_` here wraps.
    let mut out = 1usize; // pts[0] stays.
    let mut anchor = 0usize;
    let mut i = 2usize;
    while i < n {
        let (Some(&s), Some(&p)) = (pts.get(anchor), pts.get(i)) else {
            break;
        };
        if !segment_clear(grid, s, p) {
            // The node before N becomes a waypoint and the new anchor. It is always reachable
            // from the anchor (it was seen on the previous round, or it is the anchor's successor).
            anchor = i.wrapping_sub(1);
            let Some(&w) = pts.get(anchor) else { break };
            if let Some(slot) = pts.get_mut(out) {
                *slot = w;
            }
            out = out.wrapping_add(1);
            // Note: anchor < i, and the kept prefix pts[..out] never overtakes the read position
            // because out <= anchor.
        }
        i = i.wrapping_add(1);
    }
    let last = pts.get(n.wrapping_sub(1)).copied();
    if let (Some(last), Some(slot)) = (last, pts.get_mut(out)) {
        *slot = last;
    }
    out.wrapping_add(1)
}

/// [`SmoothingKind::Shortest`] with a look-back of `lookback` raw cells instead of [`LOOKBACK`]
/// (at least 1), in place, without the final collinear-point pass of [`smooth`]: for measuring
/// the choice of `K`. Falls back to the greedy rule when the scratch is short of
/// `(min(n, lookback + 1), n)` entries.
pub fn shortest_with(
    grid: &Grid<'_>,
    pts: &mut [Point],
    n: usize,
    dist: &mut [f32],
    prev: &mut PathLinks<'_>,
    lookback: usize,
) -> usize {
    let n = n.min(pts.len());
    if n < 3 {
        return n;
    }
    let lookback = lookback.max(1);
    let ring = n.min(lookback.saturating_add(1));
    if dist.len() < ring || !prev.holds(n) {
        return greedy(grid, pts, n);
    }
    let k = shortest(
        grid,
        pts,
        n,
        dist.get_mut(..ring).unwrap_or_default(),
        prev,
        lookback,
    );
    if ring < n {
        merge(grid, pts, k)
    } else {
        k
    }
}

/// Shortest subsequence path by dynamic programming, in place. `dist` is a ring of `ring =
/// min(n, lookback + 1)` entries (cell `i` in slot `i % ring`), so for `n <= lookback + 1` it is
/// the plain all-pairs DP.
fn shortest(
    grid: &Grid<'_>,
    pts: &mut [Point],
    n: usize,
    dist: &mut [f32],
    prev: &mut PathLinks<'_>,
    lookback: usize,
) -> usize {
    if let (Some(d0), false) = (dist.first_mut(), prev.is_empty()) {
        *d0 = 0.0;
        prev.link(0, 0);
    }
    dp_cells(grid, pts, dist, prev, lookback, 1..n);
    trace(pts, n, prev)
}

/// The DP for the raw cells `cells` (in order, after every cell before them): the shortest
/// distance to cell `j` over the cells at most `lookback` back that see it, into the `dist` ring
/// (cell `i` in slot `i % dist.len()`), and the chosen predecessor into `prev[j]`.
///
/// The answer for `j` is the shortest `dist[i] + |p_i p_j|` over the cells `i` that see `p_j`
/// (the previous cell always does; a tie keeps it, and otherwise the earliest `i`). The
/// candidates go earliest first, and one is tested (a segment test, the cost) only when it is
/// strictly shorter than the best clear one so far: branch and bound, no candidate order to
/// build. The set of tests is then those shorter than the answer (which every method must make,
/// having nothing else to exclude them) plus the clear ones that beat the ones before them: on
/// the colony's raw paths of the large maps 0-5 % more tests than testing in length order, since
/// most candidates are blocked and the answer is usually among the last (see [`LOOKBACK`]).
fn dp_cells(
    grid: &Grid<'_>,
    pts: &[Point],
    dist: &mut [f32],
    prev: &mut PathLinks<'_>,
    lookback: usize,
    cells: core::ops::Range<usize>,
) {
    let clear = |a: Point, b: Point| segment_clear(grid, a, b);
    scan_cells(clear, pts, dist, prev, lookback, cells, false);
}

/// How far back the bounded scan ([`chain_cells`], paths longer than [`LOOKBACK`]` + 1` cells)
/// looks: half of [`LOOKBACK`]. Its candidates are the stride cells, the chain and the near
/// cells of this window; on open ground the first stride cell that sees `j` wins and every
/// later one fails the length test, so a cell costs about one segment test of the window's
/// length. Half the window halves that (on Nav2's depot, (14,10)->(590,294), the DP 2.76 M ->
/// 1.43 M host instructions) and the merge and taut pull after the DP take back what the shorter
/// window misses: over the 80 large-map plans of `--example fingerprint -- --large 2` 15
/// smoothed lengths change, their sum by +0.0013 % (worst +0.039 %, best -0.014 %), and the
/// `large` example's smoothed/opt8 per map moves by at most 0.0003. Paths of at most
/// [`LOOKBACK`]` + 1` cells (the small maps' and the paper preset's) take the full scan, as
/// before.
pub const BOUNDED_LOOKBACK: usize = LOOKBACK / 2;

/// Predecessors of `j - 1` that the bounded scan ([`chain_cells`]) tries at most.
pub const CHAIN: usize = 16;
/// Cells just before `j - 1` whose own predecessors [`chain_cells`] also tries.
pub const NEAR: usize = 8;
/// [`chain_cells`] also tries every `STRIDE`-th cell of the look-back window.
pub const STRIDE: usize = 8;

/// The DP of a path longer than the look-back window ([`LOOKBACK`]), with a bounded candidate
/// scan. [`dp_cells`] tries every cell of the window (up to `lookback - 1` segment tests a cell:
/// 117 a cell on `maze-128-128-2`'s winding 1,380-cell path, nearly all rejected); this tries at
/// most `lookback / STRIDE + CHAIN + 2 NEAR` candidates a cell, whatever the map:
///
/// - every [`STRIDE`]-th cell of the window (fixed indices, so neighbouring cells share them),
///   earliest first: where a long straight stretch may be cut, to within `STRIDE` cells;
/// - the chain of `j - 1`'s predecessors (`prev[j - 1]`, `prev[prev[j - 1]]`, ...: the waypoints
///   of the shortest path found to `j - 1`) inside the window, at most [`CHAIN`], farthest first:
///   Theta*'s "parent of the parent", along the raw path;
/// - the [`NEAR`] cells before `j - 1` and their predecessors: the other neighbours Theta* would
///   relax `j` from.
///
/// Each is tested (a segment test) only when strictly shorter than the best clear one so far, as
/// in [`dp_cells`]; the previous cell `j - 1` is the default. What it gives up against the full
/// scan is a cut point between two stride cells that no chain passes through; the greedy pass
/// after the DP ([`merge`]) and the taut pull (`crate::polish::taut`), which moves waypoints a cell at a
/// time, take that back: on the colony's paths of the depot, Boston, New York and
/// `maze-128-128-2` the pulled result is within 0.1 % of the full scan's, shorter on some
/// (`docs/ALGORITHM.md`, "Smoothing", has the figures).
fn chain_cells(
    clear: impl FnMut(Point, Point) -> bool,
    pts: &[Point],
    dist: &mut [f32],
    prev: &mut PathLinks<'_>,
    lookback: usize,
    cells: core::ops::Range<usize>,
) {
    scan_cells(clear, pts, dist, prev, lookback, cells, true);
}

/// The DP's loop over the raw cells `cells` for both scans: every cell of the window
/// ([`dp_cells`]) or the bounded candidates ([`chain_cells`]); `clear` is the segment test.
fn scan_cells(
    mut clear: impl FnMut(Point, Point) -> bool,
    pts: &[Point],
    dist: &mut [f32],
    prev: &mut PathLinks<'_>,
    lookback: usize,
    cells: core::ops::Range<usize>,
    bounded: bool,
) {
    let ring = dist.len();
    // `ring >= 1` whenever there is a cell to do, so the `checked_rem` never fails.
    let slot = |i: usize| i.checked_rem(ring).unwrap_or(0);
    let mut chain = [0usize; CHAIN];
    for j in cells {
        let Some(&pj) = pts.get(j) else { break };
        // Default: come from the previous raw cell (always clear: it is a legal move).
        let before = j.wrapping_sub(1); // j >= 1
        let (mut best, mut from) = match (dist.get(slot(before)), pts.get(before)) {
            (Some(&d), Some(&p)) => (d + distance(p, pj), before),
            _ => break,
        };
        let lo = j.saturating_sub(lookback);
        // Branch and bound: a candidate is tested only when it would beat the best so far
        // (strictly, so a tie keeps the earlier choice found first).
        let mut try_from = |i: usize| {
            if let (Some(&di), Some(&pi)) = (dist.get(slot(i)), pts.get(i)) {
                let cand = di + distance(pi, pj);
                if cand < best && clear(pi, pj) {
                    best = cand;
                    from = i;
                }
            }
        };
        if !bounded {
            // Every cell of the window, earliest first.
            for i in lo..before {
                try_from(i);
            }
        } else {
            let near = j.saturating_sub(NEAR).max(lo);
            let mut i = lo.div_ceil(STRIDE).wrapping_mul(STRIDE);
            while i < near {
                try_from(i);
                i = i.wrapping_add(STRIDE);
            }
            // `j - 1`'s predecessors inside the window, nearest first (the start links to itself).
            let mut len = 0usize;
            let mut a = before;
            while let (Some(up), Some(s)) = (prev.from(a), chain.get_mut(len)) {
                if up >= a || up < lo {
                    break;
                }
                *s = up;
                len = len.wrapping_add(1);
                a = up;
            }
            for &i in chain.get(..len).unwrap_or_default().iter().rev() {
                try_from(i);
            }
            let mut last = usize::MAX;
            for b in near..before {
                let up = prev.from(b).unwrap_or(b);
                for i in [up, b] {
                    if i >= lo && i != last && i < before {
                        last = i;
                        try_from(i);
                    }
                }
            }
        }
        if let (Some(d), true) = (dist.get_mut(slot(j)), prev.holds(j.wrapping_add(1))) {
            *d = best;
            prev.link(j, from);
        }
    }
}

/// Follow the DP's links from the goal (`pts[n - 1]`) back to the start and compact the chosen
/// cells to the front of `pts`; returns how many.
fn trace(pts: &mut [Point], n: usize, prev: &mut PathLinks<'_>) -> usize {
    // Follow prev from the goal back to the start, reversing the links into "next" links.
    prev.reverse(n.wrapping_sub(1)); // n >= 3 (see `smooth`)

    // Walk forward, compacting the chosen cells to the front (indices only grow, so reading
    // index i after writing slot k <= i is safe).
    let mut k = 0usize;
    let mut i = 0usize;
    while let Some(&p) = pts.get(i) {
        if let Some(slot) = pts.get_mut(k) {
            *slot = p;
        }
        // The links only go forward, so at most n cells are visited: k <= n.
        k = k.wrapping_add(1);
        match prev.next(i) {
            Some(nx) => i = nx,
            None => break,
        }
    }
    k
}

/// One greedy line-of-sight pass over the waypoints `pts[..k]`, in place: a waypoint goes when
/// the last kept one sees the next one (never longer, by the triangle inequality). Returns the
/// new count. Cost: one segment test per waypoint, from the last kept one; only a stretch that
/// collapses to one long segment makes these tests grow, to `O(n^2 / K)` cells for `n` raw cells.
fn merge(grid: &Grid<'_>, pts: &mut [Point], k: usize) -> usize {
    drop_middles(pts, k, |a, _, c| segment_clear(grid, a, c))
}

/// [`merge`] from where it stands, `(i, out)` (the next interior waypoint of `pts[..k]` and the
/// waypoints kept so far, `(1, 1)` at first), while `left` lasts ([`segment_units`] a test, and
/// one): `Ok(count)` once done (what `merge` returns), `Err((i, out))` when `left` ran out first
/// (then 0). Each call with `left > 0` tries at least one waypoint. `clear` is the segment test.
fn merge_resume(
    mut clear: impl FnMut(Point, Point) -> bool,
    pts: &mut [Point],
    k: usize,
    (mut i, mut out): (usize, usize),
    left: &mut u32,
) -> Result<usize, (usize, usize)> {
    let n = k.min(pts.len());
    if n < 3 {
        return Ok(n);
    }
    // As `drop_middles`: 1 <= out <= i < n - 1 inside the loop, so no `wrapping_` here wraps.
    let last_i = n.wrapping_sub(1);
    while i < last_i {
        if *left == 0 {
            return Err((i, out));
        }
        let (Some(&a), Some(&b), Some(&c)) = (
            pts.get(out.wrapping_sub(1)),
            pts.get(i),
            pts.get(i.wrapping_add(1)),
        ) else {
            break;
        };
        *left = left.saturating_sub(segment_units(a, c).wrapping_add(1));
        if !clear(a, c) {
            if let Some(slot) = pts.get_mut(out) {
                *slot = b;
            }
            out = out.wrapping_add(1);
        }
        i = i.wrapping_add(1);
    }
    let last = pts.get(last_i).copied();
    if let (Some(last), Some(slot)) = (last, pts.get_mut(out)) {
        *slot = last;
    }
    Ok(out.wrapping_add(1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::polyline_length;

    /// No links: the smoothing takes its greedy rule.
    fn unlinked() -> PathLinks<'static> {
        PathLinks::new(&mut [])
    }

    /// The links over `words`.
    fn linked(words: &mut [u32]) -> PathLinks<'_> {
        PathLinks::new(words)
    }

    fn grid(rows: &[&str]) -> (Vec<u8>, u16, u16) {
        crate::testutil::bits(rows)
    }

    fn pts(v: &[(u16, u16)]) -> Vec<Point> {
        v.iter().map(|&(x, y)| Point::new(x, y)).collect()
    }

    #[test]
    fn open_map_collapses_to_one_segment() {
        let (b, w, h) = grid(&["......", "......", "......"]);
        let g = Grid::new(w, h, &b).unwrap();
        let raw = pts(&[(0, 0), (1, 1), (2, 1), (3, 1), (4, 2), (5, 2)]);
        for kind in [SmoothingKind::Greedy, SmoothingKind::Shortest] {
            let mut p = raw.clone();
            let mut d = vec![0.0; 6];
            let mut pr = vec![0; 6];
            let k = smooth(&g, kind, &mut p, 6, &mut d, &mut linked(&mut pr));
            assert_eq!(&p[..k], &pts(&[(0, 0), (5, 2)])[..], "{kind:?}");
        }
    }

    #[test]
    fn none_keeps_corners_only() {
        let (b, w, h) = grid(&["....", "....", "...."]);
        let g = Grid::new(w, h, &b).unwrap();
        let mut p = pts(&[(0, 0), (1, 0), (2, 0), (3, 1), (3, 2)]);
        let k = smooth(&g, SmoothingKind::None, &mut p, 5, &mut [], &mut unlinked());
        assert_eq!(&p[..k], &pts(&[(0, 0), (2, 0), (3, 1), (3, 2)])[..]);
    }

    #[test]
    fn shortest_beats_greedy_and_both_stay_clear() {
        // Raw path hugs a wall around an obstacle block.
        let rows = [
            "..........", //
            "..........", //
            "...####...", //
            "...####...", //
            "..........", //
        ];
        let (b, w, h) = grid(&rows);
        let g = Grid::new(w, h, &b).unwrap();
        // Go along row 4 under the block, then up the right side to (9, 0).
        let raw = pts(&[
            (0, 2),
            (1, 3),
            (2, 4),
            (3, 4),
            (4, 4),
            (5, 4),
            (6, 4),
            (7, 4),
            (8, 3),
            (9, 2),
            (9, 1),
            (9, 0),
        ]);
        let n = raw.len();
        let mut lens = vec![];
        for kind in [SmoothingKind::Greedy, SmoothingKind::Shortest] {
            let mut p = raw.clone();
            let mut d = vec![0.0; n];
            let mut pr = vec![0; n];
            let k = smooth(&g, kind, &mut p, n, &mut d, &mut linked(&mut pr));
            let wp = &p[..k];
            assert_eq!(wp[0], raw[0]);
            assert_eq!(wp[k - 1], raw[n - 1]);
            for s in wp.windows(2) {
                assert!(segment_clear(&g, s[0], s[1]), "{kind:?} {s:?}");
            }
            lens.push(polyline_length(wp));
        }
        assert!(lens[1] <= lens[0] + 1e-5, "{lens:?}");
        assert!(lens[1] < polyline_length(&raw));
    }

    /// The all-pairs DP as it was before the look-back (kept to prove short paths unchanged).
    fn old_shortest(g: &Grid<'_>, pts: &mut [Point], n: usize) -> usize {
        let mut dist = vec![0f32; n];
        let mut prev = vec![0u32; n];
        dist[0] = 0.0;
        for j in 1..n {
            let (mut best, mut from) = (dist[j - 1] + distance(pts[j - 1], pts[j]), j - 1);
            for i in 0..j.saturating_sub(1) {
                let cand = dist[i] + distance(pts[i], pts[j]);
                if cand < best && segment_clear(g, pts[i], pts[j]) {
                    best = cand;
                    from = i;
                }
            }
            dist[j] = best;
            prev[j] = from as u32;
        }
        let mut chain = vec![n - 1];
        while *chain.last().unwrap() != 0 {
            chain.push(prev[*chain.last().unwrap()] as usize);
        }
        chain.reverse();
        let out: Vec<Point> = chain.iter().map(|&i| pts[i]).collect();
        pts[..out.len()].copy_from_slice(&out);
        drop_collinear(pts, out.len())
    }

    /// A random map (`density` blocked) and a random walk of `steps` legal moves on it.
    fn random_walk(
        rng: &mut crate::rng::Xoshiro128pp,
        w: u16,
        h: u16,
        density: f32,
        steps: usize,
    ) -> (Vec<u8>, Vec<Point>) {
        loop {
            let b = crate::testutil::random_bits(rng, w, h, density);
            let g = Grid::new(w, h, &b).unwrap();
            let start = Point::new(
                (rng.next_word() % u32::from(w)) as u16,
                (rng.next_word() % u32::from(h)) as u16,
            );
            if !g.is_free(start) || g.move_mask(start) == 0 {
                continue;
            }
            let mut path = vec![start];
            let mut d = (rng.next_word() % 8) as u8;
            while path.len() <= steps {
                let p = *path.last().unwrap();
                // Mostly keep the heading, so walks travel instead of dithering.
                if rng.next_unit() < 0.3 {
                    d = (rng.next_word() % 8) as u8;
                }
                if let Some(q) = g.step(p, d) {
                    path.push(q);
                } else {
                    d = (rng.next_word() % 8) as u8;
                }
            }
            return (b, path);
        }
    }

    #[test]
    fn dp_matches_the_rule_tested_shortest_first() {
        // The rule as stated: the candidates `i` in `[j - LOOKBACK, j - 1)` strictly shorter than
        // coming from `j - 1`, in the order of (length bits, index), the first clear one wins
        // (the DP's order before branch and bound: a heap on those keys).
        fn rule(g: &Grid<'_>, pts: &[Point]) -> (Vec<f32>, Vec<u32>) {
            let n = pts.len();
            let (mut dist, mut prev) = (vec![0f32; n], vec![0u32; n]);
            for j in 1..n {
                let default = dist[j - 1] + distance(pts[j - 1], pts[j]);
                let mut cands: Vec<(u32, usize)> = (j.saturating_sub(LOOKBACK)..j - 1)
                    .map(|i| (dist[i] + distance(pts[i], pts[j]), i))
                    .filter(|&(c, _)| c < default)
                    .map(|(c, i)| (c.to_bits(), i))
                    .collect();
                cands.sort_unstable();
                let won = cands
                    .into_iter()
                    .find(|&(_, i)| segment_clear(g, pts[i], pts[j]));
                (dist[j], prev[j]) = match won {
                    Some((bits, i)) => (f32::from_bits(bits), i as u32),
                    None => (default, (j - 1) as u32),
                };
            }
            (dist, prev)
        }
        let mut rng = crate::rng::Xoshiro128pp::from_u64(5);
        for case in 0..120 {
            let steps = 20 + case * 9;
            // Sparse to dense maps: straight stretches (many ties and clear candidates) to
            // winding ones (most candidates blocked).
            let density = 0.02 + 0.003 * case as f32;
            let (b, raw) = random_walk(&mut rng, 90, 70, density, steps);
            let g = Grid::new(90, 70, &b).unwrap();
            let n = raw.len();
            let (want_dist, want_prev) = rule(&g, &raw);
            // The ring as long as the path, so every distance stays readable.
            let (mut dist, mut prev) = (vec![0f32; n], vec![0u32; n]);
            dp_cells(&g, &raw, &mut dist, &mut linked(&mut prev), LOOKBACK, 1..n);
            assert_eq!(prev[1..], want_prev[1..], "case {case}");
            let (bits, want_bits): (Vec<u32>, Vec<u32>) = (
                dist.iter().map(|d| d.to_bits()).collect(),
                want_dist.iter().map(|d| d.to_bits()).collect(),
            );
            assert_eq!(bits, want_bits, "case {case}");
            // The ring of the firmware (`LOOKBACK + 1` slots), in stretches of a few cells.
            let ring = n.min(LOOKBACK + 1);
            let (mut dist, mut prev) = (vec![0f32; ring], vec![0u32; n]);
            let chunk = 1 + case % 50;
            let mut j = 1;
            while j < n {
                let to = (j + chunk).min(n);
                dp_cells(&g, &raw, &mut dist, &mut linked(&mut prev), LOOKBACK, j..to);
                j = to;
            }
            assert_eq!(prev[1..], want_prev[1..], "ring, case {case}");
        }
    }

    #[test]
    fn smoothing_in_stretches_equals_smoothing_at_once() {
        let mut rng = crate::rng::Xoshiro128pp::from_u64(11);
        for case in 0..60 {
            let steps = 2 + case * 7; // short and longer than the look-back
            let (b, raw) = random_walk(&mut rng, 64, 48, 0.12, steps);
            let g = Grid::new(64, 48, &b).unwrap();
            let n = raw.len();
            for kind in SmoothingKind::ALL {
                let (mut p1, mut d1, mut r1) = (raw.clone(), vec![0.0; n], vec![0; n]);
                let k1 = smooth(&g, kind, &mut p1, n, &mut d1, &mut linked(&mut r1));
                let (mut p2, mut d2, mut r2) = (raw.clone(), vec![7.0; n], vec![9; n]);
                let mut sm = Smoother::new(kind, n, &mut d2, &mut linked(&mut r2));
                let chunk = 1 + case % 13;
                let mut calls = 0;
                while sm.resume(&g, &p2, &mut d2, &mut linked(&mut r2), chunk) {
                    calls += 1;
                }
                if kind == SmoothingKind::Shortest {
                    assert_eq!(calls, (n - 1).div_ceil(chunk) - 1, "{n} {chunk}");
                }
                let k2 = sm.finish(&g, &mut p2, &mut d2, &mut linked(&mut r2));
                assert_eq!(p1[..k1], p2[..k2], "{kind:?} case {case}");
            }
        }
    }

    #[test]
    fn the_tail_in_pieces_finishes_as_at_once() {
        // Random walks short and longer than the ring, both scans: the DP, then the tail (trace,
        // merge, taut passes) in pieces of a few work units and of many, gives `finish`'s
        // waypoints bit for bit; small budgets take many pieces.
        let mut rng = crate::rng::Xoshiro128pp::from_u64(5);
        let (mut merged, mut many) = (0, 0);
        for case in 0..40 {
            let steps = 20 + case * 13;
            let (b, raw) = random_walk(&mut rng, 64, 48, 0.12, steps);
            let g = Grid::new(64, 48, &b).unwrap();
            let n = raw.len();
            for bounded in [false, true] {
                let start = |d: &mut Vec<f32>, r: &mut Vec<u32>| {
                    let sm = Smoother::new(SmoothingKind::Shortest, n, d, &mut PathLinks::new(r));
                    if bounded {
                        sm.bounded()
                    } else {
                        sm
                    }
                };
                let (mut p1, mut d1, mut r1) = (raw.clone(), vec![0.0; n], vec![0; n]);
                let k1 = start(&mut d1, &mut r1).finish(&g, &mut p1, &mut d1, &mut linked(&mut r1));
                for budget in [1u32, 7, 60, 100_000] {
                    let (mut p2, mut d2, mut r2) = (raw.clone(), vec![0.0; n], vec![0; n]);
                    let mut sm = start(&mut d2, &mut r2);
                    while sm.resume(&g, &p2, &mut d2, &mut linked(&mut r2), 9) {}
                    let mut pieces = 1;
                    let k2 = loop {
                        if let Some(k) =
                            sm.finish_piece(&g, &mut p2, &mut d2, &mut linked(&mut r2), budget)
                        {
                            break k;
                        }
                        pieces += 1;
                        assert!(pieces < 100 * n, "no progress");
                    };
                    assert_eq!(p1[..k1], p2[..k2], "case {case} bounded {bounded} {budget}");
                    many += usize::from(pieces > 10);
                }
                merged += usize::from(n > LOOKBACK + 1);
            }
        }
        assert!(merged >= 40 && many >= 40, "{merged} {many}");
    }

    #[test]
    fn short_paths_are_bit_identical_to_the_all_pairs_dp() {
        let mut rng = crate::rng::Xoshiro128pp::from_u64(7);
        for case in 0..300 {
            let steps = 2 + case % (LOOKBACK - 1); // n = steps + 1 <= LOOKBACK + 1
            let (b, raw) = random_walk(&mut rng, 40, 30, 0.15, steps);
            let g = Grid::new(40, 30, &b).unwrap();
            let n = raw.len();
            let mut want = raw.clone();
            // The old DP, then the same taut pull the new one ends with.
            let kw = old_shortest(&g, &mut want, n);
            let kw = crate::polish::taut::pull(&g, &mut want, kw);
            let (dn, pn) = scratch_for(n);
            assert_eq!(dn, n);
            let mut got = raw.clone();
            let kg = smooth(
                &g,
                SmoothingKind::Shortest,
                &mut got,
                n,
                &mut vec![0.0; dn],
                &mut linked(&mut vec![0; pn]),
            );
            assert_eq!(&got[..kg], &want[..kw], "case {case}");
        }
    }

    #[test]
    fn long_paths_stay_valid_and_no_longer_than_greedy() {
        let mut rng = crate::rng::Xoshiro128pp::from_u64(11);
        let (mut worse, mut total_gain) = (0, 0.0f32);
        for case in 0..60 {
            let steps = 200 + case * 37;
            let (b, raw) = random_walk(&mut rng, 120, 90, 0.04 + 0.002 * case as f32, steps);
            let g = Grid::new(120, 90, &b).unwrap();
            let n = raw.len();
            let (dn, pn) = scratch_for(n);
            assert_eq!(dn, LOOKBACK + 1);
            let mut got = raw.clone();
            let k = smooth(
                &g,
                SmoothingKind::Shortest,
                &mut got,
                n,
                &mut vec![0.0; dn],
                &mut linked(&mut vec![0; pn]),
            );
            let wp = &got[..k];
            assert_eq!(wp[0], raw[0]);
            assert_eq!(wp[k - 1], raw[n - 1]);
            for s in wp.windows(2) {
                assert!(segment_clear(&g, s[0], s[1]), "case {case} {s:?}");
            }
            let mut gr = raw.clone();
            let kg = smooth(
                &g,
                SmoothingKind::Greedy,
                &mut gr,
                n,
                &mut [],
                &mut unlinked(),
            );
            let (ls, lg) = (polyline_length(wp), polyline_length(&gr[..kg]));
            assert!(ls <= polyline_length(&raw));
            if ls > lg + 1e-3 {
                worse += 1;
            }
            total_gain += lg - ls;
        }
        assert_eq!(worse, 0, "windowed DP longer than greedy in {worse} cases");
        assert!(total_gain > 0.0);
    }

    #[test]
    fn the_bounded_scan_looks_back_bounded_lookback_cells_only() {
        // A 400-cell zigzag (diagonal steps between two rows) across an open map: every cell
        // sees every earlier one and a straight cut is strictly shorter, so each cell's
        // predecessor is as far back as the scan looks. With the bounded scan that
        // is `BOUNDED_LOOKBACK` (the earliest stride cell of its window), never more; the full
        // scan on the same path goes `LOOKBACK` back. Fails if the bounded scan looks further.
        let (w, h) = (420u16, 8u16);
        let b = vec![0u8; (usize::from(w) * usize::from(h)).div_ceil(8)];
        let g = Grid::new(w, h, &b).unwrap();
        let pts: Vec<Point> = (0..400u16).map(|x| Point::new(x, 3 + x % 2)).collect();
        let n = pts.len();
        let (ring, _) = scratch_for(n);
        for (bounded, reach) in [(true, BOUNDED_LOOKBACK), (false, LOOKBACK)] {
            let (mut dist, mut prev) = (vec![0f32; ring], vec![0u32; n]);
            let mut sm = Smoother::new(
                SmoothingKind::Shortest,
                n,
                &mut dist,
                &mut linked(&mut prev),
            );
            if bounded {
                sm = sm.bounded();
            }
            while sm.resume(&g, &pts, &mut dist, &mut linked(&mut prev), 50) {}
            let farthest = (1..n).map(|j| j - prev[j] as usize).max().unwrap();
            assert!(farthest <= reach, "{bounded}: {farthest}");
            assert!(farthest > reach - STRIDE, "{bounded}: {farthest}");
        }
    }

    #[test]
    fn the_bounded_scan_tests_at_most_its_candidates_and_follows_the_full_scan() {
        // The bound: at most `LOOKBACK / STRIDE + CHAIN + 2 NEAR` segment tests a raw cell,
        // whatever the map (the full scan makes up to `LOOKBACK - 1`), and the DP stays close to
        // the full scan's: never longer than greedy, within a few per cent of the full scan.
        let bound = LOOKBACK / STRIDE + CHAIN + 2 * NEAR;
        let mut rng = crate::rng::Xoshiro128pp::from_u64(23);
        let (mut full_tests, mut chain_tests) = (0usize, 0usize);
        let (mut full_len, mut chain_len) = (0f32, 0f32);
        for case in 0..40 {
            let steps = 300 + case * 20;
            let density = 0.03 + 0.004 * case as f32;
            let (b, walk) =
                crate::testutil::heading_walk(&mut rng, 240, 120, density, steps, 2 * LOOKBACK);
            let g = Grid::new(240, 120, &b).unwrap();
            // Locally shortest first, as the planner's paths are when it smooths them.
            let mut raw = vec![Point::new(0, 0); walk.len() + 64];
            let words = crate::polish::refine::Scratch::words(52);
            let (mut sa, mut sb) = (vec![0u32; words], vec![0u32; words]);
            let scratch = crate::polish::refine::Scratch::new(&mut sa, &mut sb);
            let mut budget = crate::polish::refine::Budget::unlimited();
            let n =
                crate::polish::refine::refine(&g, &walk, &mut raw, scratch, &mut budget).unwrap();
            raw.truncate(n);
            if n <= LOOKBACK + 1 {
                continue;
            }
            let ring = n.min(LOOKBACK + 1);
            // The bounded scan, counting its tests per cell.
            let (mut dist, mut prev) = (vec![0f32; ring], vec![0u32; n]);
            let mut worst = 0usize;
            for j in 1..n {
                let mut tests = 0usize;
                let count = |a: Point, c: Point| {
                    tests += 1;
                    segment_clear(&g, a, c)
                };
                chain_cells(
                    count,
                    &raw,
                    &mut dist,
                    &mut linked(&mut prev),
                    LOOKBACK,
                    j..j + 1,
                );
                worst = worst.max(tests);
                chain_tests += tests;
            }
            assert!(worst <= bound, "case {case}: {worst} tests for one cell");
            // The smoothing as a whole (bounded DP, merge, taut pull) against the full scan's.
            let mut p = raw.clone();
            let (mut d, mut r) = (vec![0f32; ring], vec![0u32; n]);
            let k = Smoother::new(SmoothingKind::Shortest, n, &mut d, &mut linked(&mut r))
                .bounded()
                .finish(&g, &mut p, &mut d, &mut linked(&mut r));
            for s in p[..k].windows(2) {
                assert!(segment_clear(&g, s[0], s[1]), "case {case} {s:?}");
            }
            chain_len += polyline_length(&p[..k]);
            let mut q = raw.clone();
            let kq = shortest_with(&g, &mut q, n, &mut d, &mut linked(&mut r), LOOKBACK);
            let kq = drop_collinear(&mut q, kq);
            let kq = crate::polish::taut::pull(&g, &mut q, kq);
            full_len += polyline_length(&q[..kq]);
            full_tests += 1;
        }
        assert!(chain_tests > 0 && full_tests > 0);
        // Over the refined walks the bounded smoothing is within 0.5 % of the full scan's.
        assert!(
            chain_len <= full_len * 1.005,
            "{chain_len} against {full_len}"
        );
        eprintln!("bounded {chain_len} full {full_len}, tests {chain_tests}");
    }

    #[test]
    fn a_long_straight_stretch_becomes_one_segment() {
        // 600 cells along an open strip, wobbling by one row: far beyond the look-back.
        let (b, w, h) = {
            let rows: Vec<String> = (0..3).map(|_| ".".repeat(601)).collect();
            let r: Vec<&str> = rows.iter().map(String::as_str).collect();
            grid(&r)
        };
        let g = Grid::new(w, h, &b).unwrap();
        let raw: Vec<Point> = (0..=600u16)
            .map(|x| Point::new(x, if (x / 7) % 2 == 0 { 1 } else { 0 }))
            .collect();
        // Every step is a legal move (a row change is a diagonal on an open map).
        let n = raw.len();
        let (dn, pn) = scratch_for(n);
        let mut p = raw.clone();
        let k = smooth(
            &g,
            SmoothingKind::Shortest,
            &mut p,
            n,
            &mut vec![0.0; dn],
            &mut linked(&mut vec![0; pn]),
        );
        assert_eq!(&p[..k], &[raw[0], raw[n - 1]]);
        // Scratch: the ring only, not n floats.
        assert_eq!(dn, LOOKBACK + 1);
        // Too little ring: greedy (which also finds the one segment here).
        let mut q = raw.clone();
        let k = smooth(
            &g,
            SmoothingKind::Shortest,
            &mut q,
            n,
            &mut vec![0.0; LOOKBACK],
            &mut linked(&mut vec![0; n]),
        );
        assert_eq!(&q[..k], &[raw[0], raw[n - 1]]);
    }

    #[test]
    fn drop_collinear_handles_reversal() {
        // A back-and-forth on one line is a turn, not a straight point.
        let mut p = pts(&[(0, 0), (2, 0), (1, 0)]);
        assert_eq!(drop_collinear(&mut p, 3), 3);
    }
}
