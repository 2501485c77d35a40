#!/usr/bin/env python3
"""The firmware's default plan per map size: instructions under QEMU, map memory, upload.

    cargo build --release && python3 scripts/bench_sizes.py [--seeds 3]
    cargo build --release --features twin-h743 --target-dir target/twin-h743
    python3 scripts/bench_sizes.py --elf target/twin-h743/thumbv7em-none-eabihf/release/ohaca \
        [--only NewYork,Sydney]                  # the STM32H743's capacity twin, up to 1024^2

For each size (32^2 .. 512^2) one public Moving AI map of `maps/` and its longest scenario (the
largest optimum in the map's `.scen`), maze512-1-0's 4,000-step pair, and Nav2's depot at 5 cm
(without inflation, and at 0.2 m inflation with three corner-to-corner pairs; their optima are
worked out here, 8-connected without corner cutting): boots the release firmware with `-icount shift=0` (1 tick
= 1 us = 1000 instructions), uploads the map over the emulated UART in raw 128-byte chunks,
plans seeds 1..=N with the device's default parameters and prints one Markdown row per map: the
map's bytes in the device's one map buffer, the bytes a raw upload's frames put on the wire and
their time at 115200 8N1, the iterations, the instructions of the plan
(from `Run::new` to the smoothed path; `Path.ticks`), its split (with defmt-print), and the raw
length against the `.scen` optimum. A plan that fails shows its error (a path longer than the
4,095 steps the device keeps (2,047 on maps of up to 68,256 cells), 16,384 on the twin, is
`PathTooLong`). A map beyond the device's
capacity (Hello's `cells`) is uploaded all the same: its row shows the device's refusal and what
the map would need.
The planner's storage does not grow with the map (`BENCHMARKS.md` section 5).

Side by side, on the same pair and the same emulated chip: the exact A* baseline
(`examples/astar_device.rs`, `ohaca::astar`: 8-connected, no corner cutting, octile heuristic,
exact integer costs), booted once per map with `-icount shift=0` and counted from the map in RAM
to the path's cells written (SysTick, 40 instructions a cycle, calibrated by the bench itself),
in both variants: 4 bits a cell (`astar::search`: closed flag and parent in a nibble, `g` only in
the heap) and a cost a cell (`astar::search_costs`: `g` as u32 a cell, a push only when it
improves). Its columns: each variant's instructions and RAM in bytes a cell (the per-cell storage
plus the heap at its peak, over the map's cells), the 4-bit variant's expansions (the other's may differ slightly, on ties), and ohaca's
mean instructions over the 4-bit A*'s. Built if missing:
`cargo build --release --example astar_device`.
"""

import argparse
import math
import os
import re
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_device import ELF, ROOT, Qemu, mi, split_log  # noqa: E402
from ohaca_client import (Device, expect, frame, load_map, raw_cells,  # noqa: E402
                          req_hello, req_plan, req_set_map, req_set_params, varint)

# One map per size: (size class, map, scenario file), all in the repository.
MAPS = [
    ("32 x 32", "maps/movingai/random-32-32-20.map", "maps/movingai/random-32-32-20-random-1.scen"),
    ("64 x 64", "maps/large/random-64-64-10.map", "maps/large/random-64-64-10-random-1.scen"),
    ("128 x 128", "maps/large/maze-128-128-10.map", "maps/large/maze-128-128-10-random-1.scen"),
    ("128 x 128", "maps/large/maze-128-128-2.map", "maps/large/maze-128-128-2-random-1.scen"),
    ("256 x 256", "maps/large/Boston_0_256.map", "maps/large/Boston_0_256-random-1.scen"),
    ("512 x 512", "maps/large/NewYork_0_512.map", "maps/large/NewYork_0_512.map.scen"),
    # A 4,000-step way at 512 x 512 (issue 29, item 4): maze512-1-0's scenario whose optimum is
    # 4,000, within the F411's 4,095-step paths (its longest, 4,847, is beyond them).
    ("512 x 512", "maps/large/maze512-1-0.map", ((40, 125), (502, 437), 4000.0)),
    ("1024 x 1024", "maps/large/Sydney_0_1024.map", "maps/large/Sydney_0_1024.map.scen"),
    # Nav2's sample depot (host/assets/ros/, Apache-2.0) at its native 5 cm: a fixed far pair,
    # just inside the outer walls' top-left and bottom-right corners.
    ("604 x 307", "maps/depot.map", ((9, 4), (596, 300))),
    # The same depot as a robot plans on it (issue 36, item 5): inflated by 0.2 m, the robot's
    # radius (`maps/depot-r20.map`, made from the YAML as `maps/README.md` says). Three
    # corner-to-corner pairs across its open floor, each a few cells inside a corner of the free
    # space: the two diagonals and the long top side.
    ("604 x 307", "maps/depot-r20.map", ((14, 10), (590, 294))),
    ("604 x 307", "maps/depot-r20.map", ((590, 10), (14, 294))),
    ("604 x 307", "maps/depot-r20.map", ((14, 10), (590, 10))),
]
# The shared fixed map of `maps/README.md` with its stated pair and optimum.
FIXED = [("26 x 26", "maps/complex-26.map", ((0, 0), (25, 25), 41.7990))]
ASTAR_ELF = os.path.join(ROOT, "target/thumbv7em-none-eabihf/release/examples/astar_device")
CHUNK = 128
BAUD_BYTES = 115200 / 10  # 8N1: ten bits a byte


def astar_device(path, start, goal, elf=ASTAR_ELF):
    """The exact A* on the emulated chip: its `key=value` results (or `error`)."""
    cmd = ["qemu-system-arm", "-M", "mps2-an386", "-display", "none", "-monitor", "none",
           "-serial", "null", "-semihosting-config", "enable=on,target=native",
           "-icount", "shift=0", "-kernel", elf, "-append",
           f"{os.path.join(ROOT, path)} {start[0]} {start[1]} {goal[0]} {goal[1]}"]
    out = subprocess.run(cmd, capture_output=True, text=True, timeout=3600, check=False).stdout
    return dict(re.findall(r"(\w+)=(\S+)", out))


def octile_opt(path, start, goal):
    """The exact 8-connected optimum (no corner cutting) for a pair no `.scen` file states."""
    import heapq
    w, h, bits, _ = load_map(os.path.join(ROOT, path))
    blocked = lambda x, y: not (0 <= x < w and 0 <= y < h) or bits[(y * w + x) // 8] >> (
        (y * w + x) % 8) & 1
    dist = {start: 0.0}
    heap = [(0.0, start)]
    while heap:
        d, (x, y) = heapq.heappop(heap)
        if (x, y) == goal:
            return d
        if d > dist[(x, y)]:
            continue
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                if (dx, dy) == (0, 0) or blocked(x + dx, y + dy):
                    continue
                if dx and dy and (blocked(x + dx, y) or blocked(x, y + dy)):
                    continue
                nd = d + (math.sqrt(2) if dx and dy else 1.0)
                if nd < dist.get((x + dx, y + dy), math.inf):
                    dist[(x + dx, y + dy)] = nd
                    heapq.heappush(heap, (nd, (x + dx, y + dy)))
    return math.nan


def longest(scen):
    """(start, goal, optimum) of the scenario with the largest optimum."""
    if isinstance(scen, tuple):  # a fixed pair: (start, goal[, optimum])
        return scen if len(scen) == 3 else scen + (None,)
    best = None
    for line in open(os.path.join(ROOT, scen)).read().splitlines()[1:]:
        f = line.split("\t")
        if len(f) < 9:
            continue
        case = ((int(f[4]), int(f[5])), (int(f[6]), int(f[7])), float(f[8]))
        if best is None or case[2] > best[2]:
            best = case
    return best


def wire_bytes(w, h, bits):
    """Bytes on the wire of a raw upload's request frames (delimiters included; the `Ack`s travel
    the other way at the same time), as `docs/PROTOCOL.md` counts them."""
    total = 0
    for n, off in enumerate(range(0, len(bits), CHUNK)):
        body = req_set_map(w, h, off, len(bits), bits[off:off + CHUNK])
        total += len(frame(varint(n + 1) + body))
    return total


def raw_length(start, dirs):
    cells = raw_cells(start, dirs)
    return sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(cells, cells[1:]))


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--elf", default=ELF,
                    help="the firmware to boot (default: the QEMU board's release build)")
    ap.add_argument("--astar-elf", default=ASTAR_ELF,
                    help="the exact A* bench (examples/astar_device.rs) to boot")
    ap.add_argument("--no-astar", action="store_true", help="leave the exact A* columns out")
    ap.add_argument("--only", default="",
                    help="comma-separated substrings: only the maps whose file name has one")
    ap.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                    help="plan with this parameter changed from the device's defaults "
                         "(repeatable; e.g. the ablation: --param ants=1 --param iterations=1 "
                         "--param alpha=0.0 --param beta=16.0)")
    args = ap.parse_args()
    seeds = list(range(1, args.seeds + 1))
    only = [o for o in args.only.split(",") if o]
    maps = [m for m in FIXED + MAPS
            if not only or any(o in os.path.basename(m[1]) for o in only)]
    if not args.no_astar and not os.path.exists(args.astar_elf):
        subprocess.run(["cargo", "build", "--release", "--example", "astar_device"], cwd=ROOT,
                       check=True)

    rows = []
    q = Qemu(icount=True, elf=os.path.abspath(args.elf))
    plans_done = 0
    try:
        dev = Device("127.0.0.1", q.port)
        hello = expect(dev.call(req_hello()), "Hello")
        cap = hello["capacity"]
        if args.param:
            params = dict(hello["defaults"])
            for kv in args.param:
                k, v = kv.split("=")
                params[k] = float(v) if "." in v else int(v)
            expect(dev.call(req_set_params(params)), "Ack")
        for size, path, scen in maps:
            w, h, bits, _ = load_map(os.path.join(ROOT, path))
            start, goal, opt = longest(scen)
            if opt is None:
                opt = octile_opt(path, start, goal)
            wire = wire_bytes(w, h, bits)
            up = dev.set_map(w, h, bits, chunk=CHUNK)
            row = {"size": size, "map": os.path.basename(path), "start": start, "goal": goal,
                   "opt": opt, "bytes": len(bits), "wire": wire, "cells": w * h}
            if not args.no_astar:
                row["astar"] = astar_device(path, start, goal, elf=os.path.abspath(args.astar_elf))
            if up["kind"] != "Ack":
                row["refused"] = up
                rows.append(row)
                continue
            runs = [dev.call(req_plan(start, goal, seed=s)) for s in seeds]
            failed = [p for p in runs if p["kind"] != "Path"]
            if failed:  # e.g. PathTooLong: a path longer than the device keeps
                row["failed"] = failed[0]
            row["runs"] = runs
            row["first_plan"] = plans_done
            plans_done += len(runs) - len(failed)  # the firmware logs the split of a Path only
            rows.append(row)
    finally:
        log = q.stop()
    parts = split_log(log)
    if len(parts) != plans_done:
        parts = []

    print(f"Firmware `{hello['board']}` {hello['firmware_version']}: one map buffer of "
          f"{cap['cells']:,} cells ({cap['cells'] // 8:,} B, sides up to {cap['max_side']}, "
          f"paths up to {cap['max_steps']} steps); default parameters; seeds 1..={len(seeds)}; "
          f"`qemu-system-arm -icount shift=0`.\n")
    print("| size | map | longest scenario (opt8) | map in RAM | raw upload on the wire, at 115200 "
          "| iterations | instructions, mean (min-max) | `Run::new` / iterations / `finish` "
          "| raw/opt8 | exact A* 4-bit: instructions | its RAM, B/cell | A* cost a cell: "
          "instructions | its RAM, B/cell | expansions | ohaca / exact A* 4-bit |")
    print("| --- | --- | --- | ---: | --- | --- | --- | --- | --- | ---: | ---: | ---: | ---: "
          "| ---: | ---: |")
    for r in rows:
        head = (f"| {r['size']} | `{r['map']}` | {r['start']} -> {r['goal']} ({r['opt']:.2f}) | "
                f"{r['bytes']:,} B | {r['wire']:,} B, {r['wire'] / BAUD_BYTES:.1f} s | ")
        if "refused" in r:
            e = r["refused"]
            print(head + f"refused: `{e.get('name')}` (detail {e.get('detail'):,}, limit "
                  f"{e.get('limit'):,}) | | | | " + astar_cells(r, None) + " |")
            continue
        if "failed" in r:
            e = r["failed"]
            print(head + f"every plan: `{e.get('name')}` (detail {e.get('detail'):,}, limit "
                  f"{e.get('limit'):,}) | | | | " + astar_cells(r, None) + " |")
            continue
        runs = r["runs"]
        ticks = [p["ticks"] for p in runs]
        its = [p["iterations"] for p in runs]
        ratio = statistics.mean(raw_length(r["start"], p["directions"]) / r["opt"] for p in runs)
        split = ""
        if parts:
            mine = parts[r["first_plan"]:r["first_plan"] + len(runs)]
            split = " / ".join(f"{mi(statistics.mean(p[i] for p in mine)):.1f}" for i in range(3))
            split += " M"
        print(head + f"{min(its)}-{max(its)} (mean {statistics.mean(its):.1f}) | "
              f"**{mi(statistics.mean(ticks)):.2f} M** ({mi(min(ticks)):.2f}-"
              f"{mi(max(ticks)):.2f}) | {split} | {ratio:.4f} | "
              + astar_cells(r, statistics.mean(ticks) * 1000) + " |")
    return 0


def astar_cells(r, ohaca_instructions):
    """The exact A* columns of a row: each variant's instructions and B/cell, the expansions,
    ohaca / the 4-bit A*."""
    a = r.get("astar")
    if a is None:
        return " | | | | |"
    cols = []
    for p in ("", "c_"):
        if p + "error" in a or p + "instructions" not in a:
            cols += [f"`{a.get(p + 'error', 'no output')}`", ""]
            continue
        n = int(a[p + "instructions"])
        ok = abs(float(a[p + "length"]) - r["opt"]) < 1e-3
        note = "" if ok else f" (length {a[p + 'length']}!)"
        ram = int(a[p + "ram_bytes"])
        cols += [f"{n / 1e6:.2f} M{note}", f"{ram / r['cells']:.3f} ({ram:,} B)"]
    cols.append(f"{int(a['expansions']):,}" if "expansions" in a else "")
    n4 = int(a.get("instructions", 0)) if "length" in a else 0
    cols.append(f"{ohaca_instructions / n4:.1f}x" if ohaca_instructions and n4 else "")
    return " | ".join(cols)


if __name__ == "__main__":
    sys.exit(main())
