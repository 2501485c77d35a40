//! `ohaca relay`: boot the firmware ELF in QEMU (`mps2-an386`) behind a real serial line — the
//! pacing relay ([`ohaca_host::link::relay`]) at `--baud` 8N1 — and serve it on a TCP port, one
//! client at a time (`ohaca send --tcp`, `scripts/ohaca_client.py`). When a client leaves, the
//! bytes that crossed the line during its session are printed on stderr.
//!
//! QEMU's stdout (the firmware's defmt frames, through semihosting) is this command's stdout, so
//! `ohaca relay ... | defmt-print -e ELF` decodes the log; everything the relay says goes to
//! stderr. It runs until QEMU exits or it is killed (exit code 2 if QEMU or the port cannot be
//! started).

use std::net::TcpListener;
use std::path::PathBuf;
use std::process::{Command, Stdio};

use ohaca_host::exit;
use ohaca_host::link::relay::Relay;
use ohaca_host::link::DEFAULT_BAUD;

use super::bad_input;

/// Arguments of `ohaca relay`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Line speed (8N1: 10 bits a byte)
    #[arg(long, value_name = "N", default_value_t = DEFAULT_BAUD,
          value_parser = clap::value_parser!(u32).range(1..))]
    pub baud: u32,
    /// Where clients connect: HOST:PORT
    #[arg(long, value_name = "HOST:PORT", default_value = "127.0.0.1:5555")]
    pub listen: String,
    /// The firmware ELF
    #[arg(
        long,
        value_name = "PATH",
        default_value = "target/thumbv7em-none-eabihf/release/ohaca"
    )]
    pub elf: PathBuf,
    /// Run QEMU with `-icount shift=0` (virtual time: 1 ns per instruction)
    #[arg(long)]
    pub icount: bool,
}

/// Run `ohaca relay`; returns the exit code.
pub fn run(args: &Args) -> u8 {
    if !args.elf.is_file() {
        return bad_input(format!(
            "no firmware at {} (build it with `cargo build --release`, or give --elf)",
            args.elf.display()
        ));
    }
    let listener = match TcpListener::bind(&args.listen) {
        Ok(l) => l,
        Err(e) => return bad_input(format!("cannot listen on {}: {e}", args.listen)),
    };
    let mut qemu = Command::new("qemu-system-arm");
    qemu.args(["-M", "mps2-an386", "-display", "none", "-monitor", "none"])
        .args(["-semihosting-config", "enable=on,target=native"]);
    if args.icount {
        qemu.args(["-icount", "shift=0"]);
    }
    qemu.arg("-kernel")
        .arg(&args.elf)
        .stdin(Stdio::null())
        .stdout(Stdio::inherit())
        .stderr(Stdio::inherit());
    let (mut child, relay) = match Relay::spawn_qemu(&mut qemu, args.baud) {
        Ok(r) => r,
        Err(e) => return bad_input(format!("cannot start qemu-system-arm: {e}")),
    };
    eprintln!(
        "ohaca relay: firmware {} in QEMU{}, UART at {} baud 8N1 on {}",
        args.elf.display(),
        if args.icount { " (icount shift=0)" } else { "" },
        args.baud,
        args.listen
    );
    let counters = relay.counters();
    // QEMU's exit ends the relay (the device side closes) and then this loop: a client that is
    // connected reads end-of-file; a waiting `accept` is left by the process exit below.
    let watcher = std::thread::spawn(move || {
        let status = child.wait();
        eprintln!("ohaca relay: QEMU exited ({status:?})");
        std::process::exit(i32::from(exit::BAD_INPUT));
    });
    for client in listener.incoming() {
        let client = match client {
            Ok(c) => c,
            Err(e) => {
                eprintln!("ohaca relay: accept: {e}");
                continue;
            }
        };
        let peer = client
            .peer_addr()
            .map_or_else(|_| "?".to_string(), |a| a.to_string());
        eprintln!("ohaca relay: client {peer} connected");
        match relay.serve(client) {
            Ok(s) => eprintln!(
                "ohaca relay: client {peer} left: {s}; {} lost in all, at most {} bytes written \
                 by QEMU ahead of the line",
                counters.to_device_dropped(),
                counters.backlog_max()
            ),
            Err(e) => eprintln!("ohaca relay: client {peer}: {e}"),
        }
        if counters.device_closed() {
            break;
        }
    }
    drop(watcher);
    exit::BAD_INPUT
}
