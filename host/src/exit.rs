//! The exit codes of the `ohaca` tool, shared by every subcommand so scripts can rely on them.
//!
//! | code | meaning |
//! | --- | --- |
//! | 0 | a path was found |
//! | 1 | no path: the goal is unreachable (or, with `--dead-end die`, no ant reached it) |
//! | 2 | bad input: unreadable or malformed map, bad parameter, start/goal outside the map or on an obstacle, bad command line |

/// A path was found.
pub const FOUND: u8 = 0;
/// The run was valid but there is no path.
pub const NO_PATH: u8 = 1;
/// The input was rejected (map file, parameters, start/goal, command line). Also clap's code for
/// usage errors.
pub const BAD_INPUT: u8 = 2;
