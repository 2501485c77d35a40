#!/usr/bin/env bash
# Install defmt-print (the decoder of the firmware's defmt log) into cargo's bin directory
# (~/.cargo/bin) if it is not on PATH yet; used by scripts/golden-boot.sh and scripts/test.sh.
#
# It is built unoptimised and without debuginfo (`--debug`, `profile.dev.debug=false`): about
# 75 s of CPU instead of the release build's 190 s (its dependencies include tokio and clap),
# and it still decodes the boot log in 0.1 s (0.01 s optimised). An optimised one that is already
# installed is kept; `cargo install defmt-print --locked --force` replaces this one with one.
set -euo pipefail

if command -v defmt-print >/dev/null 2>&1; then
  exit 0
fi
echo "installing defmt-print: cargo install defmt-print --locked --debug" >&2
# exec: the caller's pid is cargo's (scripts/test.sh stops it if the tests fail first).
exec cargo install defmt-print --locked --debug --config profile.dev.debug=false
