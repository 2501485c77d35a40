//! The core under std against independent references: one test binary (`cargo test -p
//! ohaca-host-tests --test it`), one module per subject, so the dependency graph is linked once
//! rather than once per file. Run one module with a filter, e.g. `--test it -- properties::`.
//! Proptest keeps failing inputs next to each module (`astar.regressions`, ...: `gen::config`).

// The exact A* against the `.scen` optima and `reference::astar8`.
mod astar;
// The corridor search against the any-angle reference.
mod corridor;
// Figures in the documents that a test can produce.
mod documents;
// Fresh wide-corridor mazes: the default plan stays near the optimum.
mod mazes;
// The colony's move budget on `maze-128-128-10`.
mod move_budget;
// The paper's rules, pinned numerically.
mod paper_rules;
// The planner's properties on small random maps.
mod properties;
// The references reproduce the documented optima.
mod references;
// The local search `ohaca::refine`.
mod refine;
// Replans answered with the rest of the last answer.
mod reuse;
// Every shared scenario over seeds 1..=30: validity and quality targets.
mod shared_maps;
