#!/usr/bin/env bash
# Exact instruction profile of one plan on the QEMU firmware, by function and source line
# (see scripts/profile_device.py). Takes about half a minute and a few hundred MB in $TMPDIR.
#
#   scripts/profile-device.sh [--no-build] [--map maps/complex-26.map] [--start 0,0] [--goal X,Y]
#                             [--seed 1] [--param patience=0]
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" = "--no-build" ]; then
  shift
else
  cargo build --release -q
fi
exec python3 scripts/profile_device.py "$@"
