#!/usr/bin/env bash
# Run every test of ohaca: core unit tests and doc tests, host-tool tests, property tests,
# shared-map checks, and the firmware's end-to-end tests under QEMU.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

# The core's unit tests and doc examples, on the host.
cargo test -p ohaca --target host-tuple
# Host tool, references, properties, shared maps, QEMU end-to-end (release: the shared-map
# quality runs plan thousands of times).
cargo build --release
cargo test --release -p ohaca-host -p ohaca-host-tests --target host-tuple
