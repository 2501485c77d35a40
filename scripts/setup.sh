#!/usr/bin/env bash
# Install what a fresh Debian machine with Rust (rustup) lacks for ohaca: the Cortex-M4F target,
# rustfmt/clippy, and QEMU. Idempotent; sourced by scripts/demo.sh and scripts/test.sh.
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
