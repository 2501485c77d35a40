//! `ohaca`, the host tool. One subcommand per module under `src/cmd/` (those modules belong to
//! this binary, not to the library): each has an `Args` struct (clap derive) and a `run` that
//! returns the exit code (see [`ohaca_host::exit`]). Adding a subcommand (`send`, `render`,
//! `experiment`, `bench`) means a new module and one new [`Command`] variant; nothing in `plan`
//! changes.
#![deny(unsafe_code)]
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing,
    clippy::unreachable,
    clippy::todo,
    clippy::unimplemented
)]

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod cmd;

/// Plan robot paths with the Optimized Hybrid Ant Colony algorithm (and ACA, PACA, HACA).
///
/// Exit codes: 0 path found, 1 no path, 2 bad input.
#[derive(Parser, Debug)]
#[command(name = "ohaca", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Plan a path on a map file and print it (ASCII picture, JSON or CSV: --format)
    Plan(cmd::plan::Args),
    /// Plan and draw the map with the paths (and the pheromone) into an SVG or PNG file
    Render(cmd::render::Args),
    /// Run the algorithms many times each; write CSV, a summary and charts into a folder
    Experiment(cmd::experiment::Args),
    /// Plan on the firmware over TCP (QEMU) or a serial port; prints what `plan` prints
    Send(cmd::send::Args),
    /// Drive a robot through map changes and replan warm or cold (host core or a device)
    Replan(cmd::replan::Args),
    /// Run as a ROS 2 node: /map, /goal_pose, /initialpose in, /plan and Nav2's
    /// compute_path_to_pose out (host core or a device)
    Ros(Box<cmd::ros::Args>),
    /// Boot the firmware in QEMU behind a real serial line (--baud 8N1) and serve it on a TCP
    /// port, one client at a time
    Relay(cmd::relay::Args),
    /// Check a path in metres (JSON [[x, y], ...]) against a map: start, goal, free segments
    Check(cmd::check::Args),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return ExitCode::from(usage_error(&e)),
    };
    let code = match cli.command {
        Command::Plan(args) => cmd::plan::run(&args),
        Command::Render(args) => cmd::render::run(&args),
        Command::Experiment(args) => cmd::experiment::run(&args),
        Command::Send(args) => cmd::send::run(&args),
        Command::Replan(args) => cmd::replan::run(&args),
        Command::Ros(args) => cmd::ros::run(&args),
        Command::Relay(args) => cmd::relay::run(&args),
        Command::Check(args) => cmd::check::run(&args),
    };
    ExitCode::from(code)
}

/// Report a command-line error. Help, version and "no subcommand" go through clap as usual; a
/// real usage error (bad number, unknown flag, missing argument) becomes one `error: ...` line on
/// stderr, like every other bad input, with exit code 2.
fn usage_error(e: &clap::Error) -> u8 {
    use clap::error::ErrorKind;
    if !e.use_stderr() || e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
        // Help or version: clap prints it and exits (0, or 2 for the bare `ohaca`).
        e.exit();
    }
    let text = e.render().to_string();
    let line = one_line(&text);
    cmd::bad_input(line.strip_prefix("error: ").unwrap_or(&line))
}

/// clap's message without the usage and hint lines, joined into one line.
fn one_line(text: &str) -> String {
    text.lines()
        .map(str::trim)
        .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .filter(|l| !l.is_empty() && !l.starts_with("tip:"))
        .collect::<Vec<_>>()
        .join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// clap's own consistency checks of every subcommand (argument ids in `conflicts_with`,
    /// `required_unless_present` and `mut_arg`, groups, ...).
    #[test]
    fn command_line_is_consistent() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }
}
