#!/usr/bin/env bash
# Install what a fresh Debian machine with Rust (rustup) lacks for ohaca: the Cortex-M4F target,
# rustfmt/clippy, QEMU, and Python's cyclonedds (the C library of Eclipse Cyclone DDS in a wheel,
# for `ohaca ros`'s interoperability test). Idempotent; sourced by scripts/demo.sh and scripts/test.sh.
set -euo pipefail

need_root() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

if ! rustup target list --installed 2>/dev/null | grep -qx thumbv7em-none-eabihf; then
  rustup target add thumbv7em-none-eabihf
fi
for c in rustfmt clippy llvm-tools; do
  if ! rustup component list --installed 2>/dev/null | grep -q "^$c"; then
    rustup component add "$c" || rustup component add "$c-preview" || true
  fi
done
if ! command -v qemu-system-arm >/dev/null 2>&1; then
  need_root env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  need_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq qemu-system-arm >/dev/null
fi
# `ohaca ros`'s interoperability test (scripts/ros_interop.py) plays ROS 2 with Cyclone DDS: the
# PyPI wheel bundles its C library. Debian's own Python is "externally managed" (PEP 668): pip
# needs --break-system-packages there (as root in CI, or into ~/.local otherwise).
if ! python3 -c 'import cyclonedds' >/dev/null 2>&1; then
  if ! python3 -m pip --version >/dev/null 2>&1; then
    need_root env DEBIAN_FRONTEND=noninteractive apt-get update -qq
    need_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3 python3-pip >/dev/null
  fi
  python3 -m pip install -q --disable-pip-version-check cyclonedds 2>/dev/null \
    || python3 -m pip install -q --disable-pip-version-check --break-system-packages cyclonedds
  python3 -c 'import cyclonedds'
fi
