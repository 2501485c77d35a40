#!/usr/bin/env bash
# Count the panic call sites left in a release firmware ELF and say whose code each one is in.
# Every call to a panicking function (core::panicking::*, slice index failures, unwrap failures,
# RefCell borrow failures, defmt's panic) is traced through its inline chain (the release profile
# keeps debug info) to the innermost frame in this repository's src/, and counted there.
# Usage: scripts/panic-sites.sh [ELF]   (default: the QEMU firmware; built if missing)
# Exits 1 if any site is in the planner core or the protocol (src/*.rs but main.rs, src/protocol/).
set -euo pipefail
cd "$(dirname "$0")/.."
elf="${1:-target/thumbv7em-none-eabihf/release/ohaca}"
[ -f "$elf" ] || cargo build --release
objdump="$(ls "$(rustc --print sysroot)"/lib/rustlib/*/bin/llvm-objdump 2>/dev/null | head -1 || true)"
if [ -z "$objdump" ]; then
  rustup component add llvm-tools >/dev/null 2>&1
  objdump="$(ls "$(rustc --print sysroot)"/lib/rustlib/*/bin/llvm-objdump | head -1)"
fi
command -v addr2line >/dev/null || { echo "addr2line (binutils) is needed" >&2; exit 2; }
pattern=$'\tbl?\t.*<(core::panicking::|_defmt_panic|core::cell::panic_|core::slice::.*_fail|core::result::unwrap_failed|core::option::(unwrap|expect)_failed)'
mapfile -t addrs < <("$objdump" -d --no-show-raw-insn -C "$elf" | grep -E "$pattern" | awk '{print "0x" $1}' | tr -d ':')
report=$(mktemp)
if [ "${#addrs[@]}" -gt 0 ]; then
  addr2line -a -i -C -e "$elf" "${addrs[@]}" | awk -v root="$PWD/" '
    function flush() { if (addr != "") print (owner == "" ? "(dependencies only)" : owner) }
    /^0x/ { flush(); addr = $0; owner = ""; next }
    # A frame whose line is unknown (`file:?`: code the compiler merged, its location lost) is no
    # evidence of who owns the call: skip it (e.g. embassy-sync'"'"'s `unwrap!` of a `try_borrow_mut`
    # inlined into the planner task showed up as `src/planner/reuse.rs:?`).
    index($0, root "src/") == 1 && owner == "" && $0 !~ /:\?( |$)/ { owner = substr($0, length(root) + 1); sub(/ .*/, "", owner) }
    END { flush() }' | sed -E "s/:([0-9]+|\?)( .*)?$//" | sort | uniq -c | sort -rn > "$report"
fi
total=$(awk '{s += $1} END {print s + 0}' "$report")
core=$(awk '$2 ~ /^src\// && $2 !~ /^src\/(main\.rs|firmware\/)/ {s += $1} END {print s + 0}' "$report")
cat "$report"
echo "panic call sites in $elf: $total, of which $core in the planner core and protocol"
rm -f "$report"
[ "$core" -eq 0 ]
