//! The subcommands, one module each, plus the output helpers they share.

pub mod check;
pub mod experiment;
pub mod plan;
pub mod relay;
pub mod render;
pub mod replan;
pub mod ros;
pub mod send;

use std::io::Write;

use ohaca_host::exit;

/// Print `error: {msg}` as one line on stderr and return [`exit::BAD_INPUT`].
pub fn bad_input(msg: impl std::fmt::Display) -> u8 {
    let _ = writeln!(std::io::stderr().lock(), "error: {msg}");
    exit::BAD_INPUT
}

/// Write `text` to stdout. A closed pipe (`ohaca ... | head`) is not an error worth a panic;
/// it is reported on stderr and the exit code stays as it was.
pub fn print(text: &str) {
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        if e.kind() != std::io::ErrorKind::BrokenPipe {
            let _ = writeln!(std::io::stderr().lock(), "error: cannot write output: {e}");
        }
    }
}
