//! The paper's rules, pinned numerically through the public API:
//!
//! - the pheromone update (eq. 11-13) of whole iterations of [`Run::step_observed`], recomputed by
//!   hand from the tours the ants walked, for every edge of the table, with and without the
//!   wolves rule, with the bounds in play, in a storage that keeps the iteration's best and worst
//!   paths and in one that walks those ants again (as every firmware board does): the
//!   production path of the wolves rule (`update::wolves`, called by the colony) both ways;
//! - the wolves rule's reading (`docs/ALGORITHM.md`): the worst ants' deposits are withdrawn
//!   exactly (with one worst ant, `w = 1`, its own deposit), the best ants' deposit doubled;
//! - a map where only reinforcement finds the short route (no heuristic: `beta = 0`, or no goal
//!   attraction: `a = 1`), and where HACA's wolves rule measurably beats PACA;
//! - the paper preset ([`Params::paper`]) and its trip through the protocol.

use ohaca::grid::Dir;
use ohaca::pheromone::edge;
use ohaca::protocol::{decode_request, encode_request, Request, MAX_REQUEST_WIRE};
use ohaca::{plan, Algorithm, DeadEnd, Params, Point, Run, SmoothingKind};
use ohaca_host_tests::maps::{maps_dir, Map};

/// `(straight, diagonal)` steps of a tour.
fn steps(tour: &[Dir]) -> (u32, u32) {
    let diagonal = tour.iter().filter(|&&d| d % 2 == 1).count() as u32;
    (tour.len() as u32 - diagonal, diagonal)
}

fn length((s, k): (u32, u32)) -> f64 {
    f64::from(s) + f64::from(k) * std::f64::consts::SQRT_2
}

/// Run `iterations` iterations of a fresh run; the tours of each and the table at the end. With
/// `replaying`, the storage has no buffers for the iteration's best and worst paths: the run
/// walks those ants again for the wolves rule, as the devices do.
fn run_steps(
    map: &Map,
    start: Point,
    goal: Point,
    p: &Params,
    iterations: usize,
    replaying: bool,
) -> (Vec<Vec<Vec<Dir>>>, Vec<[f32; 4]>) {
    let grid = map.grid();
    let mut storage = ohaca_host_tests::heap::storage(map.cells());
    if replaying {
        storage = storage.replaying();
    }
    let mut all = Vec::new();
    {
        let mut run = Run::new(&grid, start, goal, p, storage.workspace()).expect("run");
        for _ in 0..iterations {
            let mut tours = Vec::new();
            run.step_observed(|t| tours.push(t.to_vec()));
            all.push(tours);
        }
    }
    let tau = storage.workspace().pheromone()[..map.cells()].to_vec();
    (all, tau)
}

/// What one iteration must do to `tau`, by the paper's eq. 11-13 and our readings, in f64:
/// every ant deposits `Q / L_k` on its path; with the wolves rule, the first ant of the best
/// length deposits `b Q / L_b` more on its path (`b` = ants of that length) and the first ant of
/// the worst length withdraws `w Q / L_w` from its path (`w` = ants of that length), unless all
/// lengths are equal; then `tau = clamp((1 - rho) tau + delta, tau_min, tau_max)`.
fn expected_update(
    map: &Map,
    start: Point,
    p: &Params,
    tau: &[[f64; 4]],
    tours: &[Vec<Dir>],
) -> Vec<[f64; 4]> {
    let grid = map.grid();
    let q = f64::from(p.q);
    let mut delta = vec![[0.0f64; 4]; tau.len()];
    let mut add = |tour: &[Dir], amount: f64| {
        let mut c = start;
        for &d in tour {
            let (cell, slot) = edge(map.width(), c, d).expect("edge on the map");
            delta[cell][slot] += amount;
            c = grid.step(c, d).expect("an allowed move");
        }
    };
    for t in tours {
        add(t, q / length(steps(t)));
    }
    if p.algorithm.wolves() && !tours.is_empty() {
        let lens: Vec<(u32, u32)> = tours.iter().map(|t| steps(t)).collect();
        let best = *lens
            .iter()
            .min_by(|a, b| length(**a).total_cmp(&length(**b)))
            .unwrap();
        let worst = *lens
            .iter()
            .max_by(|a, b| length(**a).total_cmp(&length(**b)))
            .unwrap();
        if best != worst {
            let b = lens.iter().filter(|l| **l == best).count() as f64;
            let w = lens.iter().filter(|l| **l == worst).count() as f64;
            let ib = lens.iter().position(|l| *l == best).unwrap();
            let iw = lens.iter().position(|l| *l == worst).unwrap();
            add(&tours[ib], b * q / length(best));
            add(&tours[iw], -(w * q / length(worst)));
        }
    }
    let (lo, hi) = (f64::from(p.tau_min), f64::from(p.tau_max));
    let keep = 1.0 - f64::from(p.rho);
    tau.iter()
        .zip(&delta)
        .map(|(t, d)| std::array::from_fn(|s| (keep * t[s] + d[s]).clamp(lo, hi)))
        .collect()
}

/// How often the iterations of `tours` had several best ants on different paths, and how many
/// iterations had different lengths at all (so the wolves rule acted).
fn tie_stats(tours: &[Vec<Vec<Dir>>]) -> (usize, usize) {
    let mut tied = 0;
    let mut spread = 0;
    for it in tours {
        let lens: Vec<(u32, u32)> = it.iter().map(|t| steps(t)).collect();
        let Some(best) = lens
            .iter()
            .min_by(|a, b| length(**a).total_cmp(&length(**b)))
        else {
            continue;
        };
        let mut paths: Vec<&Vec<Dir>> = it.iter().filter(|t| steps(t) == *best).collect();
        paths.dedup();
        paths.sort();
        paths.dedup();
        tied += usize::from(paths.len() > 1);
        spread += usize::from(lens.iter().any(|l| l != best));
    }
    (tied, spread)
}

fn complex() -> Map {
    Map::load(maps_dir().join("complex-26.map")).expect("complex-26.map")
}

#[test]
fn pheromone_update_is_eq_11_to_13_on_every_edge() {
    let map = complex();
    let (start, goal) = (Point::new(0, 0), Point::new(25, 25));
    let cases = [
        (
            "paca default",
            Params {
                algorithm: Algorithm::Paca,
                ..Params::default()
            },
        ),
        (
            "haca default",
            Params {
                algorithm: Algorithm::Haca,
                ..Params::default()
            },
        ),
        (
            "haca paper",
            Params {
                algorithm: Algorithm::Haca,
                ..Params::paper()
            },
        ),
        (
            "aca paper",
            Params {
                algorithm: Algorithm::Aca,
                ..Params::paper()
            },
        ),
        (
            // Both bounds in play: rewards hit tau_max, evaporation and punishment tau_min.
            "haca tight bounds",
            Params {
                algorithm: Algorithm::Haca,
                tau_min: 0.93,
                tau_max: 1.02,
                rho: 0.3,
                ..Params::paper()
            },
        ),
        (
            "ohaca q alpha rho",
            Params {
                q: 3.0,
                alpha: 2.0,
                rho: 0.5,
                tighten: false,
                ..Params::default()
            },
        ),
    ];
    const STEPS: usize = 3;
    let mut tied = 0;
    for ((name, p), replaying) in cases.iter().flat_map(|c| [(c, false), (c, true)]) {
        let p = *p;
        for seed in 1..=2 {
            // No early stop: every one of the STEPS iterations runs (the default's runs that
            // refine may stop after 2).
            let p = Params {
                seed,
                patience: 0,
                refine_patience: 0,
                warm_patience: 0,
                ..p
            };
            let mut want = vec![[f64::from(p.tau0); 4]; map.cells()];
            for k in 1..=STEPS {
                // A fresh run of k iterations walks the same ants as a longer one.
                let (tours, tau) = run_steps(&map, start, goal, &p, k, replaying);
                want = expected_update(&map, start, &p, &want, &tours[k - 1]);
                for (i, (g, w)) in tau.iter().zip(&want).enumerate() {
                    for s in 0..4 {
                        let (g, w) = (f64::from(g[s]), w[s]);
                        assert!(
                            (g - w).abs() <= 2e-5 * w.abs().max(1.0),
                            "{name} (replaying {replaying}) seed {seed} iteration {k}: \
                             cell {:?} slot {s}: {g} vs {w}",
                            map.point(i)
                        );
                    }
                }
                if k == STEPS && p.algorithm.wolves() {
                    let (t, spread) = tie_stats(&tours);
                    assert!(spread > 0, "{name}: the wolves rule never acted");
                    tied += t;
                }
            }
        }
    }
    // The tie rule (the first best ant's path gets b Q / L_b) was exercised.
    assert!(tied > 0, "no iteration had best ants on different paths");
}

/// The corridor map: from `S` the short route runs east (10 steps), the long one down, east and
/// up (18 steps). With no heuristic, only the pheromone can tell them apart.
const FORK: [&str; 6] = [
    "###########", //
    "...........", //
    ".#########.", //
    ".#########.", //
    ".#########.", //
    "...........", //
];
const FORK_START: Point = Point::new(0, 1);
const FORK_GOAL: Point = Point::new(10, 1);

/// The share of ants on the short route in each iteration (from the curve's mean length).
fn short_share(p: &Params) -> Vec<f64> {
    let map = Map::from_rows(&FORK);
    let mut storage = ohaca_host_tests::heap::storage(map.cells());
    let plan = plan(&map.grid(), FORK_START, FORK_GOAL, p, storage.workspace()).expect("plan");
    assert_eq!(plan.raw_length, 10.0);
    plan.curve()
        .iter()
        .map(|c| (18.0 - f64::from(c.mean)) / 8.0)
        .collect()
}

fn fork_params(algorithm: Algorithm, beta: f32, a: f32, seed: u64) -> Params {
    Params {
        algorithm,
        beta,
        a,
        seed,
        // The paper's 50 ants (the default has 12): the shares below are over 50 walks.
        ants: 50,
        iterations: 60,
        patience: 0,
        refine_patience: 0,
        ..Params::default()
    }
}

#[test]
fn reinforcement_alone_finds_the_short_route() {
    // beta = 0 (no heuristic at all) and a = 1 (no goal attraction; both first steps are
    // straight, so eta is the same): the first iteration splits the ants about evenly, and only
    // the pheromone deposits (Q / L: more per ant on the short route) can move them.
    for (beta, a) in [(0.0, 0.05), (2.0, 1.0)] {
        for algorithm in [Algorithm::Aca, Algorithm::Paca] {
            for seed in 1..=5 {
                let share = short_share(&fork_params(algorithm, beta, a, seed));
                let what = format!("{algorithm} beta {beta} a {a} seed {seed}");
                assert!(
                    (0.25..=0.75).contains(&share[0]),
                    "{what}: first iteration {}",
                    share[0]
                );
                let last = *share.last().unwrap();
                assert!(
                    last >= 0.9,
                    "{what}: last iteration only {last} on the short route"
                );
            }
        }
    }
}

/// First iteration in which at least `share` of the ants took the short route.
fn iterations_to(shares: &[f64], share: f64) -> usize {
    shares
        .iter()
        .position(|s| *s >= share)
        .unwrap_or(shares.len())
}

#[test]
fn the_wolves_rule_makes_haca_converge_faster_than_paca() {
    // Same seeds, same first iteration; then HACA rewards the short route twice and withdraws
    // the long route's deposits, PACA only deposits Q / L. Counted in iterations, never in time.
    let mut paca_total = 0;
    let mut haca_total = 0;
    for seed in 1..=8 {
        let paca = short_share(&fork_params(Algorithm::Paca, 0.0, 0.05, seed));
        let haca = short_share(&fork_params(Algorithm::Haca, 0.0, 0.05, seed));
        assert_eq!(
            paca[0], haca[0],
            "seed {seed}: the first iteration is the same walk"
        );
        let (tp, th) = (iterations_to(&paca, 0.95), iterations_to(&haca, 0.95));
        assert!(th < tp, "seed {seed}: HACA took {th} iterations, PACA {tp}");
        paca_total += tp;
        haca_total += th;
    }
    println!(
        "iterations to 95 % on the short route over 8 seeds: PACA {paca_total}, HACA {haca_total}"
    );
    assert!(
        2 * haca_total < paca_total,
        "PACA {paca_total}, HACA {haca_total}"
    );
}

#[test]
fn the_worst_ants_deposits_are_withdrawn_and_the_best_doubled() {
    // One HACA iteration on the fork with beta = 0: every ant took one of two paths, so all the
    // worst ants share one path (w of them) and all the best ants the other (b of them).
    let map = Map::from_rows(&FORK);
    let p = Params {
        algorithm: Algorithm::Haca,
        ..fork_params(Algorithm::Haca, 0.0, 0.05, 3)
    };
    let (tours, tau) = run_steps(&map, FORK_START, FORK_GOAL, &p, 1, false);
    let b = tours[0].iter().filter(|t| t.len() == 10).count() as f32;
    let w = tours[0].iter().filter(|t| t.len() == 18).count() as f32;
    assert_eq!(b + w, 50.0);
    assert!(b > 0.0 && w > 0.0);
    let tau_at = |p: Point, d: Dir| {
        let (c, s) = edge(map.width(), p, d).unwrap();
        tau[c][s]
    };
    // The long route's first edge (south from the start): its w ants' deposits w Q / 18 are
    // taken back by the punishment w Q / L_w; only evaporation is left, as if no ant had gone.
    let long = tau_at(FORK_START, 2);
    assert!((long - 0.9).abs() < 1e-5, "long route {long}");
    // The short route's first edge (east): b Q / 10 deposited plus b Q / 10 reward.
    let short = tau_at(FORK_START, 0);
    let want = 0.9 + 2.0 * b / 10.0;
    assert!((short - want).abs() < 1e-5, "short route {short} vs {want}");
    // With w = 1 the punishment is the single worst ant's own deposit: same result.
    let mut one = None;
    for seed in 1..400 {
        let p = Params { seed, ants: 3, ..p };
        let (tours, tau) = run_steps(&map, FORK_START, FORK_GOAL, &p, 1, false);
        if tours[0].iter().filter(|t| t.len() == 18).count() == 1 {
            one = Some((tours, tau));
            break;
        }
    }
    let (_, tau) = one.expect("a seed where one of three ants takes the long route");
    let (c, s) = edge(map.width(), FORK_START, 2).unwrap();
    assert!((tau[c][s] - 0.9).abs() < 1e-6, "w = 1: {}", tau[c][s]);
}

#[test]
fn the_paper_preset_is_the_papers_algorithm() {
    let p = Params::paper();
    assert_eq!(
        (p.alpha, p.beta, p.rho, p.q, p.a, p.xi, p.ants, p.iterations),
        (1.0, 2.0, 0.1, 1.0, 0.05, 1.0, 50, 100)
    );
    assert_eq!(p.dead_end, DeadEnd::Die);
    assert_eq!(p.smoothing, SmoothingKind::Greedy);
    assert!(!p.tighten);
    // Patience 0: always the full N iterations, however early the best path is found.
    let map = complex();
    let mut storage = ohaca_host_tests::heap::storage(map.cells());
    let plan = plan(
        &map.grid(),
        Point::new(0, 0),
        Point::new(25, 25),
        &p,
        storage.workspace(),
    )
    .expect("plan");
    assert_eq!(plan.iterations, 100);
    assert!(plan.best_iteration < 99);
}

#[test]
fn the_paper_preset_travels_through_the_protocol() {
    for p in [
        Params::paper(),
        Params {
            seed: u64::MAX,
            algorithm: Algorithm::Haca,
            ..Params::paper()
        },
    ] {
        let mut buf = [0u8; MAX_REQUEST_WIRE];
        let n = encode_request(9, &Request::SetParams(p), &mut buf).expect("encode");
        let (id, back) = decode_request(&mut buf[..n - 1]).expect("decode");
        assert_eq!(id, 9);
        assert_eq!(back, Request::SetParams(p));
    }
}
