//! Replays every saved input through its target's checks: the crash reproducers in
//! `fuzz/regressions/<target>/` and the seeds in `fuzz/seeds/<target>/`.
//!
//! ```text
//! cd fuzz && cargo test --target x86_64-unknown-linux-gnu
//! ```

use std::fs;
use std::path::Path;

fn replay(dir: &str, check: fn(&[u8])) -> usize {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let Ok(entries) = fs::read_dir(&dir) else {
        return 0;
    };
    let mut files: Vec<_> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    files.sort();
    let mut n = 0;
    for f in files.iter().filter(|f| f.is_file()) {
        if f.extension().is_some_and(|e| e == "md") {
            continue;
        }
        let data = fs::read(f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        eprintln!("replaying {}", f.display());
        check(&data);
        n += 1;
    }
    n
}

#[test]
fn frame_inputs() {
    replay(
        "regressions/wire_frame",
        ohaca_fuzz::wire_frame::fuzz_wire_frame,
    );
    assert!(
        replay("seeds/wire_frame", ohaca_fuzz::wire_frame::fuzz_wire_frame) > 0,
        "no wire_frame seeds"
    );
}

#[test]
fn map_parser_inputs() {
    replay(
        "regressions/map_parsers",
        ohaca_fuzz::maps::fuzz_map_parsers,
    );
    assert!(
        replay("seeds/map_parsers", ohaca_fuzz::maps::fuzz_map_parsers) > 0,
        "no map seeds"
    );
}

/// The seeds must reach the success paths, not just the error ones.
#[test]
fn seeds_are_accepted() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("seeds");
    for e in fs::read_dir(dir.join("wire_frame")).unwrap() {
        let f = e.unwrap().path();
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        let (req, rep) = ohaca_fuzz::wire_frame::check_streams(&fs::read(&f).unwrap());
        if name.starts_with("req-") || name.starts_with("session-") {
            assert!(req >= 1, "{name}: no request decoded");
        }
        if name.starts_with("rep-") && name != "rep-too-large" {
            assert!(rep >= 1, "{name}: no reply decoded");
        }
        if name.starts_with("too-large") {
            assert_eq!(req, 1, "{name}: the Hello after the long frame");
        }
    }
    for e in fs::read_dir(dir.join("map_parsers")).unwrap() {
        let f = e.unwrap().path();
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        let ok = ohaca_fuzz::maps::check_map_input(&fs::read(&f).unwrap());
        assert!(ok, "{name}: no map loaded");
    }
}

#[test]
fn planner_inputs() {
    replay("regressions/planner", ohaca_fuzz::fuzz_planner);
}

/// Pseudo-random planner inputs (a fixed xorshift stream, so the same every run), long enough to
/// reach the trailing fields: the local search, its patience and the map tiling that makes maps
/// large enough for it (more than 1,024 cells). Each input runs as decoded and again with valid
/// parameters and the local search on (random parameters are rarely valid). A quick stand-in
/// for `scripts/fuzz.sh planner`.
#[test]
fn random_planner_inputs_keep_every_promise() {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut large = 0;
    for _ in 0..600 {
        let data: Vec<u8> = (0..200)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 24) as u8
            })
            .collect();
        let mut u = arbitrary::Unstructured::new(&data);
        let Ok(mut input) = <ohaca_fuzz::PlannerInput as arbitrary::Arbitrary>::arbitrary(&mut u)
        else {
            continue;
        };
        ohaca_fuzz::check_planner(&input);
        let cells = usize::from(input.width) * usize::from(input.height);
        large += usize::from(cells > ohaca::pheromone::BLOCKS);
        input.params = ohaca::Params {
            seed: input.params.seed,
            ants: 8,
            iterations: 6,
            refine: true,
            refine_patience: input.params.refine_patience,
            ..ohaca::Params::default()
        };
        ohaca_fuzz::check_planner(&input);
    }
    assert!(
        large >= 50,
        "only {large} inputs large enough for the local search"
    );
}
