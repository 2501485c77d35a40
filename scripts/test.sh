#!/usr/bin/env bash
# Run every test of ohaca: the core's unit tests and doc examples, the protocol's byte-exact
# document test, the host tool's tests, the exact references and property tests, the shared-map
# checks, the firmware under QEMU (end-to-end over its emulated UART, and its golden boot log), and
# `ohaca ros` against Cyclone DDS (on the QEMU firmware and on the host core).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

# The core (planner + protocol): unit tests and doc examples, on the host.
cargo test -p ohaca --target host-tuple
# The QEMU firmware the end-to-end tests boot, and the STM32H743's QEMU capacity twin (the
# H743's capacity and RAM regions on the same QEMU board) that host/tests/qemu_twin.rs boots.
cargo build --release
cargo build --release --features twin-h743 --target-dir target/twin-h743
# Host tool (incl. QEMU end-to-end tests, the twin's on 1024 x 1024 and 2048 x 1024 maps),
# references, properties, shared maps. Profile `host` (Cargo.toml): optimised, since the
# shared-map checks plan thousands of times, without the firmware's fat LTO. It also builds the
# `ohaca` tool the tests run, target/<host>/host/ohaca, which ros-test.sh below reuses.
cargo test --profile host -p ohaca-host -p ohaca-host-tests --target host-tuple
# The firmware's boot log against tests/golden/boot.txt, and the protocol selftest over QEMU.
scripts/golden-boot.sh --no-build
scripts/qemu-selftest.sh --no-build
# `ohaca ros` as a ROS 2 node against Eclipse Cyclone DDS, loopback only: on the QEMU firmware,
# then on the host core (map, poses, plan, a map update's warm replan, the Nav2 action).
scripts/ros-test.sh --no-build
