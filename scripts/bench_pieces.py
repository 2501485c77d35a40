#!/usr/bin/env python3
"""The largest piece of work between two yields of the firmware's planner, per plan (issue 38).

    cargo build --release && python3 scripts/bench_pieces.py [--seeds 1] [--only NewYork,depot-r20]
    cargo build --release --features twin-h743 --target-dir target/twin-h743
    python3 scripts/bench_pieces.py --elf target/twin-h743/thumbv7em-none-eabihf/release/ohaca \\
        --only Sydney

Boots the firmware with `-icount shift=0` (1 tick = 1 us = 1,000 instructions exactly), uploads
each map of the table below, plans its pair with seeds 1..=N and the device's defaults, and reads
the firmware's defmt log line of each plan (`src/firmware/plan.rs`): the plan's instructions, the
largest piece (one `Run::poll`, or `Run::new`, or `Run::finish`) and the stage it was in, and the
largest piece of each stage. Needs defmt-print (scripts/install-defmt-print.sh). Prints one
Markdown row per plan.
"""

import argparse
import hashlib
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_device import ELF, ROOT, Qemu  # noqa: E402
from ohaca_client import Device, expect, load_map, req_hello, req_plan  # noqa: E402

MAPS = [
    ("maps/large/NewYork_0_512.map", (509, 443), (0, 9)),
    ("maps/depot-r20.map", (14, 10), (590, 294)),
    ("maps/large/maze512-1-0.map", (40, 125), (502, 437)),
    ("maps/large/Sydney_0_1024.map", None, None),
    ("maps/large/maze-128-128-2.map", (86, 122), (17, 99)),  # its longest scenario (random-1)
]
LINE = re.compile(r"plan (\d+): (\d+) iterations, .* (\d+) ticks \(new \d+, steps \d+, finish \d+\), "
                  r"largest piece (\d+) ticks \((\w+); new (\d+), setup (\d+) (\w*), "
                  r"colony (\d+) (\w*), polish (\d+) (\w*), finish (\d+)\)")


def longest(map_path):
    best = None
    for line in open(os.path.join(ROOT, map_path + ".scen")).read().splitlines()[1:]:
        f = line.split("\t")
        if len(f) >= 9 and (best is None or float(f[8]) > best[2]):
            best = ((int(f[4]), int(f[5])), (int(f[6]), int(f[7])), float(f[8]))
    return best[0], best[1]


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=1)
    ap.add_argument("--elf", default=ELF)
    ap.add_argument("--only", default="")
    args = ap.parse_args()
    only = [o for o in args.only.split(",") if o]
    maps = [m for m in MAPS if not only or any(o in os.path.basename(m[0]) for o in only)]
    q = Qemu(icount=True, elf=os.path.abspath(args.elf))
    asked = []
    try:
        dev = Device("127.0.0.1", q.port)
        hello = expect(dev.call(req_hello()), "Hello")
        for path, start, goal in maps:
            if start is None:
                start, goal = longest(path)
            w, h, bits, _ = load_map(os.path.join(ROOT, path))
            up = dev.set_map(w, h, bits, chunk=128)
            if up["kind"] != "Ack":
                print(f"{path}: refused {up}", file=sys.stderr)
                continue
            for seed in range(1, args.seeds + 1):
                r = dev.call(req_plan(start, goal, seed=seed))
                asked.append((path, start, goal, seed, r))
    finally:
        log = q.stop()
    lines = [m.groups() for m in LINE.finditer(log)]
    print(f"Firmware `{hello['board']}`; `qemu-system-arm -icount shift=0`; instructions in M "
          "(ticks / 1000).\n")
    print("| map | pair | seed | iterations | plan | largest piece (stage) | new | setup | colony "
          "| polish | finish | path |")
    print("| --- | --- | ---: | ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: | --- |")
    k = 0
    for path, start, goal, seed, r in asked:
        if r["kind"] != "Path":
            print(f"| `{os.path.basename(path)}` | {start} -> {goal} | {seed} | {r} |")
            continue
        # The path's fingerprint: its directions and waypoints (device paths must not change).
        digest = hashlib.sha256(repr((r["directions"], r["waypoints"])).encode()).hexdigest()[:12]
        if k >= len(lines):  # a firmware without the line: the plan's instructions only
            print(f"| `{os.path.basename(path)}` | {start} -> {goal} | {seed} | "
                  f"{r['iterations']} | {r['ticks'] / 1000:.3f} | | | | | | | `{digest}` |")
            continue
        g = lines[k]
        k += 1
        m = lambda t: f"{int(t) / 1000:.3f}"
        print(f"| `{os.path.basename(path)}` | {start} -> {goal} | {seed} | {g[1]} | {m(r['ticks'])} "
              f"| **{m(g[3])}** ({g[4]}) | {m(g[5])} | {m(g[6])} {g[7]} | {m(g[8])} {g[9]} "
              f"| {m(g[10])} {g[11]} | {m(g[12])} | `{digest}` |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
