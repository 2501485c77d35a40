//! The large public Moving AI maps of `maps/large/` (cities, game maps, warehouses, mazes, rooms)
//! with the scenarios of largest optimum of each, for the large-map tests and examples.

use std::path::Path;

use crate::maps::{load_scen, longest, maps_dir, Case, Map};

/// A large map and its longest scenarios.
#[derive(Clone, Debug)]
pub struct LargeMap {
    /// File stem, e.g. `Boston_0_256`.
    pub name: String,
    /// The map.
    pub map: Map,
    /// Its longest scenarios (stated 8-connected optimum in `stated_opt8`).
    pub cases: Vec<Case>,
}

/// The large maps, smallest first, each with its `scenarios` longest `.scen` entries (the MAPF
/// `-random-1.scen` file where there is one, else the Moving AI `.map.scen` file).
///
/// # Panics
/// If a file is missing or malformed (these are the repository's own files).
pub fn large_maps(scenarios: usize) -> Vec<LargeMap> {
    let dir = maps_dir().join("large");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| {
            let p = e.ok()?.path();
            (p.extension()? == "map").then(|| p.file_stem()?.to_str().map(str::to_string))?
        })
        .collect();
    names.sort();
    let mut out: Vec<LargeMap> = names
        .into_iter()
        .map(|name| load_large(&dir, &name, scenarios))
        .collect();
    out.sort_by_key(|m| (m.map.cells(), m.name.clone()));
    out
}

/// One large map by name with its `scenarios` longest scenarios.
pub fn load_large(dir: &Path, name: &str, scenarios: usize) -> LargeMap {
    let map = Map::load(dir.join(format!("{name}.map"))).unwrap_or_else(|e| panic!("{e}"));
    let random = dir.join(format!("{name}-random-1.scen"));
    let scen = if random.exists() {
        random
    } else {
        dir.join(format!("{name}.map.scen"))
    };
    let entries = load_scen(&scen).unwrap_or_else(|e| panic!("{e}"));
    LargeMap {
        name: name.to_string(),
        map,
        cases: longest(entries, scenarios),
    }
}
