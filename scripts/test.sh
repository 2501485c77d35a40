#!/usr/bin/env bash
# Run every test of ohaca: the core's unit tests and doc examples, the protocol's byte-exact
# document test, the host tool's tests, the exact references and property tests, the shared-map
# checks, the firmware under QEMU (end-to-end over its emulated UART, and its golden boot log), and
# `ohaca ros` against Cyclone DDS (on the QEMU firmware and on the host core).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

# Cargo builds one thing at a time in a target directory, so the two builds that have their own
# run in the background while the rest builds in target/ (on a fresh clone that saves a minute or
# two of the first run): the STM32H743's QEMU capacity twin (the H743's capacity and RAM regions
# on the same QEMU board) that host/tests/qemu/twin_maps.rs boots, and defmt-print, if missing, which
# golden-boot.sh decodes the boot log with and host/tests/qemu/responsive.rs the firmware's
# latency log (scripts/install-defmt-print.sh). Their output goes to
# a log that is shown if they fail.
logs=$(mktemp -d)
twin_pid=""
defmt_pid=""
cleanup() {
  for p in $twin_pid $defmt_pid; do kill "$p" 2>/dev/null || true; done
  rm -rf "$logs"
}
trap cleanup EXIT
# join NAME PID: wait for a background build; on failure, show its log and stop.
join() {
  if wait "$2"; then
    echo "$1: built" >&2
  else
    echo "FAIL: $1 (background build):" >&2
    cat "$logs/$1" >&2
    exit 1
  fi
}
echo "building the H743 twin firmware in the background (target/twin-h743)" >&2
cargo build --release --features twin-h743 --target-dir target/twin-h743 >"$logs/twin-h743" 2>&1 &
twin_pid=$!
if ! command -v defmt-print >/dev/null 2>&1; then
  echo "installing defmt-print in the background (scripts/install-defmt-print.sh)" >&2
  scripts/install-defmt-print.sh >"$logs/defmt-print" 2>&1 &
  defmt_pid=$!
fi

# The core (planner + protocol): unit tests and doc examples, on the host.
cargo test -p ohaca --target host-tuple
# The QEMU firmware the end-to-end tests boot.
cargo build --release
join twin-h743 "$twin_pid"
twin_pid=""
# defmt-print decodes the firmware's log for host/tests/qemu/responsive.rs (request and reply
# ticks) and qemu/pieces.rs (the largest piece of a plan, counted under -icount), and for
# golden-boot.sh below.
if [ -n "$defmt_pid" ]; then
  join defmt-print "$defmt_pid"
  defmt_pid=""
fi
# Host tool (incl. QEMU end-to-end tests, the twin's on 1024 x 1024 and 2048 x 1024 maps),
# references, properties, shared maps. Profile `host` (Cargo.toml): optimised, since the
# shared-map checks plan thousands of times, without the firmware's fat LTO. It also builds the
# `ohaca` tool the tests run, target/<host>/host/ohaca, which ros-test.sh below reuses. The
# libraries, the tool and the three test binaries (host/tests/qemu/, host/tests/tool/,
# host-tests/tests/it/) only: not the 12 examples, which plain `cargo test` would also build and
# link, optimised (CI's `cargo clippy --all-targets` compiles them; the crates have no doc tests).
cargo test --profile host -p ohaca-host -p ohaca-host-tests --target host-tuple --lib --bins --tests
# The firmware's boot log against tests/golden/boot.txt, and the protocol selftest over QEMU.
scripts/golden-boot.sh --no-build
scripts/qemu-selftest.sh --no-build
# `ohaca ros` as a ROS 2 node against Eclipse Cyclone DDS, loopback only: on the QEMU firmware,
# then on the host core (map, poses, plan, a map update's warm replan, the Nav2 action).
scripts/ros-test.sh --no-build
