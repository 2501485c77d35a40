//! Quality of the default plan on freshly generated small maps (not the shared ones): random
//! obstacles at 10, 20 and 30 % on 24 x 24 and 32 x 32 maps, random start/goal pairs at least half
//! the map apart, seeded so every run generates the same maps.
//!
//! ```text
//! cargo run --profile host -p ohaca-host-tests --target host-tuple --example fresh -- [--maps N] [--seeds N]
//! ```
//!
//! Prints, per density: runs, valid, mean and worst raw length over the exact 8-connected optimum,
//! mean and worst smoothed length over the exact any-angle optimum (both from
//! `ohaca_host_tests::reference`).

use ohaca::{plan, Params, Point};
use ohaca_host_tests::check::check_plan;
use ohaca_host_tests::gen::Mix;
use ohaca_host_tests::maps::Map;
use ohaca_host_tests::reference::optima;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (mut maps, mut seeds) = (20u64, 5u64);
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let v: u64 = it.next().and_then(|v| v.parse().ok()).expect("a number");
        match flag.as_str() {
            "--maps" => maps = v,
            "--seeds" => seeds = v,
            _ => panic!("usage: fresh [--maps N] [--seeds N]"),
        }
    }
    println!("| obstacles | runs | valid | raw/opt8 mean | max | smoothed/any-angle mean | max |");
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: |");
    let (mut all_raw, mut all_smooth, mut all_n) = (0.0, 0.0, 0u64);
    for density in [10u64, 20, 30] {
        let mut rng = Mix(density);
        let (mut n, mut valid, mut raw, mut smooth) = (0u64, 0u64, 0.0f64, 0.0f64);
        let (mut raw_max, mut smooth_max) = (1.0f64, 1.0f64);
        let mut made = 0;
        while made < maps {
            let side = if rng.below(2) == 0 { 24 } else { 32 };
            let blocked: Vec<bool> = (0..side * side).map(|_| rng.below(100) < density).collect();
            let mut m = Map::new(side as u16, side as u16, blocked);
            let pick = |r: &mut Mix| Point::new(r.below(side) as u16, r.below(side) as u16);
            let (s, g) = (pick(&mut rng), pick(&mut rng));
            let far =
                (i32::from(s.x) - i32::from(g.x)).abs() + (i32::from(s.y) - i32::from(g.y)).abs();
            if far < side as i32 / 2 {
                continue;
            }
            m.set(s, false);
            m.set(g, false);
            let Some(opt) = optima(&m, s, g) else {
                continue;
            };
            made += 1;
            for seed in 1..=seeds {
                let p = Params {
                    seed,
                    ..Params::default()
                };
                let mut st = ohaca_host_tests::heap::storage(m.cells());
                let plan = plan(&m.grid(), s, g, &p, st.workspace()).expect("reachable");
                n += 1;
                valid += u64::from(check_plan(&m, s, g, &plan, usize::MAX).is_ok());
                let r = f64::from(plan.raw_length) / opt.opt8;
                let q = f64::from(plan.length) / opt.any_angle;
                raw += r;
                smooth += q;
                raw_max = raw_max.max(r);
                smooth_max = smooth_max.max(q);
            }
        }
        println!(
            "| {density} % | {n} | {valid} | {:.4} | {raw_max:.4} | {:.4} | {smooth_max:.4} |",
            raw / n as f64,
            smooth / n as f64
        );
        all_raw += raw;
        all_smooth += smooth;
        all_n += n;
    }
    println!(
        "\nall: raw/opt8 {:.4}, smoothed/any-angle {:.4} over {all_n} runs",
        all_raw / all_n as f64,
        all_smooth / all_n as f64
    );
}
