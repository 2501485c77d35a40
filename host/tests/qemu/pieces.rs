//! The planner's pieces on the device are bounded by count (issue 38, item 1): the firmware
//! drives `Run::poll` and yields after every piece, and no piece of a plan may take more than
//! 1 M instructions (10 ms at 100 MHz), on the large maps where a piece was largest (the
//! coarse route of NewYork_0_512 was 6.3 M instructions in one piece, an iteration on Nav2's
//! depot 5.9 M, before the pieces were bounded), and on the mazes, whose long paths made the
//! largest pieces once those were bounded (a walk's tightening on maze-128-128-2, 1.27 M, and on
//! maze512 with its smoothing's tail, 1.56 M, until both went in pieces too).
//!
//! The firmware (F411-capacity QEMU build) runs under `qemu-system-arm -icount shift=0`, where
//! its timer counts executed instructions exactly (a tick is 1 us of virtual time = 1,000
//! instructions), and logs each plan's largest piece in ticks (`src/firmware/plan.rs`); the test
//! decodes that defmt log with `defmt-print` (scripts/install-defmt-print.sh, which
//! `scripts/test.sh` runs first) and asserts the bound, a count, never a wall time.
//!
//! Without `qemu-system-arm` it fails unless `OHACA_SKIP_QEMU=1`.

use crate::qemu;

use std::net::TcpStream;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use ohaca::Point;
use ohaca_host::link::Link;
use ohaca_host::Map;
use qemu::{firmware, free_port, have_qemu, longest_scenario, maps, TIMEOUT};

/// The bound of a piece, in ticks of `-icount shift=0` (1,000 instructions each): 1 M
/// instructions.
const MOST_TICKS: u64 = 1_000;

/// QEMU with `-icount shift=0`, UART0 on a free TCP port and the defmt log in `log`.
fn boot(log: &std::path::Path) -> (std::process::Child, String) {
    let port = free_port();
    let child = Command::new("qemu-system-arm")
        .args(["-M", "mps2-an386", "-display", "none", "-monitor", "none"])
        .args(["-semihosting-config", "enable=on,target=native"])
        .args(["-icount", "shift=0"])
        .args([
            "-serial",
            &format!("tcp:127.0.0.1:{port},server=on,wait=off,nodelay=on"),
        ])
        .arg("-kernel")
        .arg(firmware())
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(log).expect("the log file"))
        .stderr(Stdio::inherit())
        .spawn()
        .expect("start qemu-system-arm");
    let addr = format!("127.0.0.1:{port}");
    let t0 = Instant::now();
    while TcpStream::connect(&addr).is_err() {
        assert!(t0.elapsed() < Duration::from_secs(30), "QEMU's UART port");
        std::thread::sleep(Duration::from_millis(20));
    }
    (child, addr)
}

/// The `largest piece N ticks (name; ...)` of every plan in the decoded log, in order.
fn largest_pieces(log: &str) -> Vec<(u64, String)> {
    log.lines()
        .filter_map(|l| {
            let rest = l.split("largest piece ").nth(1)?;
            let mut words = rest.split_whitespace();
            let ticks = words.next()?.parse().ok()?;
            let name = words.nth(1)?.trim_start_matches('(').trim_end_matches(';');
            Some((ticks, name.to_string()))
        })
        .collect()
}

#[test]
fn no_piece_of_a_large_plan_exceeds_a_million_instructions() {
    need_qemu!();
    let dir = std::env::temp_dir().join(format!("ohaca-pieces-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let log = dir.join("defmt.bin");
    let (mut child, addr) = boot(&log);
    let (ny_start, ny_goal) = longest_scenario("large/NewYork_0_512.map.scen");
    // Each map with its seeds (maze512's plan alone is 164 M instructions: one seed).
    let cases: [(&str, Point, Point, &[u64]); 4] = [
        ("large/NewYork_0_512.map", ny_start, ny_goal, &[1, 2]),
        (
            "depot-r20.map",
            Point::new(14, 10),
            Point::new(590, 294),
            &[1, 2],
        ),
        // Its longest scenario (random-1), as `scripts/bench_pieces.py` plans it.
        (
            "large/maze-128-128-2.map",
            Point::new(86, 122),
            Point::new(17, 99),
            &[1, 2],
        ),
        (
            "large/maze512-1-0.map",
            Point::new(40, 125),
            Point::new(502, 437),
            &[1],
        ),
    ];
    let mut plans = Vec::new();
    {
        let mut link = Link::tcp(&addr, TIMEOUT).expect("connect");
        for (name, start, goal, seeds) in cases {
            let map = Map::load(maps().join(name)).expect(name);
            link.set_map(&map).expect("upload");
            for &seed in seeds {
                let path = link.plan(start, goal, Some(seed)).expect("a path");
                plans.push((name, seed, path.ticks));
            }
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    let decoded = Command::new("defmt-print")
        .arg("-e")
        .arg(firmware())
        .args(["--log-format", "{s}"])
        .stdin(std::fs::File::open(&log).expect("the log"))
        .output()
        .expect("defmt-print (scripts/install-defmt-print.sh) decodes the firmware's log");
    let _ = std::fs::remove_dir_all(&dir);
    let text = String::from_utf8_lossy(&decoded.stdout);
    let pieces = largest_pieces(&text);
    assert_eq!(pieces.len(), plans.len(), "one line a plan:\n{text}");
    for ((name, seed, ticks), (piece, what)) in plans.iter().zip(&pieces) {
        println!("{name} seed {seed}: {ticks} ticks, largest piece {piece} ticks ({what})");
        // A plan of many pieces: its largest piece is a small share of it.
        assert!(*ticks > 4 * MOST_TICKS, "{name}: a plan of {ticks} ticks");
        assert!(
            *piece <= MOST_TICKS,
            "{name} seed {seed}: a piece ({what}) of {piece} ticks (x 1,000 instructions)"
        );
    }
}
