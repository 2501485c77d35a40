#!/usr/bin/env python3
"""Where a plan's instructions go, exactly, under QEMU. Run through scripts/profile-device.sh.

Boots the QEMU firmware with `-icount shift=0 -d in_asm,exec,nochain` (QEMU logs every translated
block's instructions and every block it executes), uploads a map, runs one plan, stops QEMU, and
counts the executed instructions per address. Each address is mapped through the ELF's debug
info (addr2line -i: the inline chain, since LTO inlines the whole planner into one task) to the
innermost function and line in this repository's src/; code outside src/ (compiler builtins such
as fmaxf or __aeabi_ldivmod, libm, embassy) is listed under its own symbol. The counts cover the
whole session (boot, upload, plan: the plan is nearly all of it); the log is a few hundred MB,
deleted at the end.
"""

import argparse
import bisect
import collections
import os
import re
import socket
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ohaca_client import Device, expect, load_map, req_plan, req_set_params, req_hello  # noqa

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ELF = os.path.join(ROOT, "target/thumbv7em-none-eabihf/release/ohaca")
SRC = os.path.join(ROOT, "src") + "/"


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def run_session(trace, args):
    port = free_port()
    qemu = subprocess.Popen(
        ["qemu-system-arm", "-M", "mps2-an386", "-display", "none", "-monitor", "none",
         "-semihosting-config", "enable=on,target=native",
         "-serial", f"tcp:127.0.0.1:{port},server=on,wait=off,nodelay=on",
         "-icount", "shift=0", "-d", "in_asm,exec,nochain", "-D", trace, "-kernel", ELF],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        dev = Device("127.0.0.1", port, timeout=900.0)  # tracing is slow
        hello = expect(dev.call(req_hello()), "Hello")
        w, h, bits, _ = load_map(args.map)
        expect(dev.set_map(w, h, bits), "Ack")
        params = dict(hello["defaults"])
        for kv in args.param:
            k, v = kv.split("=")
            params[k] = float(v) if "." in v else int(v)
        expect(dev.call(req_set_params(params)), "Ack")
        goal = tuple(int(v) for v in args.goal.split(",")) if args.goal else (w - 1, h - 1)
        start = tuple(int(v) for v in args.start.split(","))
        r = expect(dev.call(req_plan(start, goal, seed=args.seed)), "Path")
        return r
    finally:
        qemu.terminate()
        qemu.wait()


def count(trace):
    """Executions per guest instruction address."""
    tb = {}  # host code pointer -> guest addresses of the block
    pending = None
    counts = collections.Counter()
    trace_re = re.compile(r"^Trace \d+: (0x[0-9a-f]+) ")
    ins_re = re.compile(r"^0x([0-9a-f]+):")
    with open(trace, errors="replace") as f:
        for line in f:
            if line.startswith("Trace"):
                m = trace_re.match(line)
                if not m:
                    continue
                if pending is not None:
                    tb[m.group(1)] = pending
                    pending = None
                for a in tb.get(m.group(1), ()):
                    counts[a] += 1
            elif line.startswith("IN:"):
                pending = []
            elif pending is not None:
                m = ins_re.match(line)
                if m:
                    pending.append(int(m.group(1), 16))
    return counts


def symbols():
    out = subprocess.run(["nm", "-n", "-C", ELF], capture_output=True, text=True).stdout
    syms = []
    for line in out.splitlines():
        parts = line.split(" ", 2)
        if len(parts) == 3 and parts[1] in "tT" and not parts[2].startswith("$"):
            syms.append((int(parts[0], 16) & ~1, parts[2]))
    return syms


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--map", default=os.path.join(ROOT, "maps/complex-26.map"))
    ap.add_argument("--start", default="0,0")
    ap.add_argument("--goal", help="default: the map's far corner")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--param", action="append", default=[], help="e.g. patience=0")
    ap.add_argument("--top", type=int, default=25)
    args = ap.parse_args()

    with tempfile.TemporaryDirectory(prefix="ohaca-profile-") as tmp:
        trace = os.path.join(tmp, "trace.log")
        plan = run_session(trace, args)
        counts = count(trace)
    total = sum(counts.values())
    addrs = sorted(counts)
    a2l = subprocess.run(["addr2line", "-a", "-i", "-f", "-C", "-e", ELF]
                         + [hex(a) for a in addrs], capture_output=True, text=True).stdout
    chains, cur, lines = {}, None, a2l.splitlines()
    i = 0
    while i < len(lines):
        if lines[i].startswith("0x"):
            cur = int(lines[i], 16)
            chains[cur] = []
            i += 1
        elif cur is not None and i + 1 < len(lines):
            chains[cur].append((lines[i], lines[i + 1]))
            i += 2
        else:
            i += 1
    syms = symbols()
    starts = [s[0] for s in syms]

    by_fn, by_line, by_file = collections.Counter(), collections.Counter(), collections.Counter()
    for a, c in counts.items():
        frame = next(((fn, loc) for fn, loc in chains.get(a, []) if loc.startswith(SRC)), None)
        if frame:
            fn, loc = frame
            loc = loc[len(ROOT) + 1:].split(" ")[0]
            by_fn[fn.split("::{{closure}}")[0]] += c
            by_line[f"{loc}  ({fn.split('::')[-1]})"] += c
            by_file[loc.split(":")[0]] += c
        else:
            k = bisect.bisect_right(starts, a) - 1
            name = syms[k][1] if k >= 0 else "?"
            by_fn[f"{name} (outside src/)"] += c
            by_file["(outside src/)"] += c

    print(f"Plan: seed {args.seed}, {plan['iterations']} iterations, {plan['ticks']} ticks "
          f"(= {plan['ticks'] / 1000:.2f} M instructions from Run::new to the result). "
          f"Whole session: {total / 1e6:.2f} M instructions.\n")
    for title, ctr, n in [("file", by_file, 12), ("function (innermost in src/)", by_fn, args.top),
                          ("line", by_line, args.top)]:
        print(f"| {title} | instructions | share |")
        print("| --- | --- | --- |")
        for k, c in ctr.most_common(n):
            print(f"| `{k}` | {c / 1e6:.3f} M | {100 * c / total:.1f}% |")
        print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
