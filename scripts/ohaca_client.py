#!/usr/bin/env python3
"""A small, dependency-free client for the ohaca firmware protocol (docs/PROTOCOL.md).

Talks to the firmware over TCP (QEMU's `-serial tcp:...`, see scripts/qemu-serve.sh). Meant for
checking the firmware by hand and from scripts; the real host tool is `ohaca send`.

  scripts/ohaca_client.py --port 4444 hello
  scripts/ohaca_client.py --port 4444 plan --map maps/complex-26.map --start 0,0 --goal 25,25
  scripts/ohaca_client.py --port 4444 stats
  scripts/ohaca_client.py --port 4444 selftest     # every request and error path, asserts
  scripts/ohaca_client.py --port 4444 stack        # the deepest-stack requests, then Stats.stack_peak
"""

import argparse
import socket
import struct
import sys
import time
import zlib

# ---- postcard primitives ---------------------------------------------------------------------


def varint(n):
    out = bytearray()
    while True:
        b = n & 0x7F
        n >>= 7
        if n:
            out.append(b | 0x80)
        else:
            out.append(b)
            return bytes(out)


def f32(x):
    return struct.pack("<f", x)


def byte_str(b):
    return varint(len(b)) + bytes(b)


class Reader:
    def __init__(self, data):
        self.d = data
        self.i = 0

    def byte(self):
        b = self.d[self.i]
        self.i += 1
        return b

    def varint(self):
        n, shift = 0, 0
        while True:
            b = self.byte()
            n |= (b & 0x7F) << shift
            shift += 7
            if not b & 0x80:
                return n

    def f32(self):
        (x,) = struct.unpack_from("<f", self.d, self.i)
        self.i += 4
        return x

    def bytes(self):
        n = self.varint()
        b = self.d[self.i : self.i + n]
        if len(b) != n:
            raise ValueError("truncated")
        self.i += n
        return bytes(b)

    def str(self):
        return self.bytes().decode()

    def done(self):
        return self.i == len(self.d)


# ---- framing ---------------------------------------------------------------------------------


def cobs_encode(data):
    out = bytearray([0])
    code_at, code = 0, 1
    for b in data:
        if b == 0:
            out[code_at] = code
            code_at, code = len(out), 1
            out.append(0)
        else:
            out.append(b)
            code += 1
            if code == 0xFF:
                out[code_at] = code
                code_at, code = len(out), 1
                out.append(0)
    out[code_at] = code
    return bytes(out)


def cobs_decode(data):
    out = bytearray()
    i = 0
    while i < len(data):
        code = data[i]
        if code == 0:
            raise ValueError("zero in COBS frame")
        i += 1
        run = data[i : i + code - 1]
        if len(run) != code - 1:
            raise ValueError("COBS run past the end")
        out += run
        i += code - 1
        if code != 0xFF and i < len(data):
            out.append(0)
    return bytes(out)


def frame(body):
    return cobs_encode(body + struct.pack("<I", zlib.crc32(body))) + b"\x00"


def unframe(wire):
    p = cobs_decode(wire)
    if len(p) < 5:
        raise ValueError("frame too short")
    body, crc = p[:-4], struct.unpack("<I", p[-4:])[0]
    if zlib.crc32(body) != crc:
        raise ValueError("bad CRC")
    return body


# ---- messages --------------------------------------------------------------------------------

PROTOCOL_VERSION = 10
ALGORITHMS = ["aca", "paca", "haca", "ohaca"]
DEAD_ENDS = ["backtrack", "die"]
SMOOTHING = ["none", "greedy", "shortest"]
ERRORS = {
    1: "BadMap", 2: "MapTooLarge", 3: "StartOutOfBounds", 4: "GoalOutOfBounds",
    5: "StartBlocked", 6: "GoalBlocked", 7: "BadParam", 8: "NoPath", 9: "Cancelled",
    10: "NoAntArrived", 11: "PathTooLong", 16: "BadCrc", 17: "Undecodable", 18: "TooLarge", 19: "NoMap",
    20: "Busy", 21: "BadChunk", 22: "Internal", 23: "BadRle", 24: "OutsideMap",
}
PARAM_FIELDS = [
    ("algorithm", "enum"), ("ants", "u"), ("iterations", "u"), ("alpha", "f"), ("beta", "f"),
    ("rho", "f"), ("q", "f"), ("a", "f"), ("xi", "f"), ("tau0", "f"), ("tau_min", "f"),
    ("tau_max", "f"), ("patience", "u"), ("warm_patience", "u"), ("refine_patience", "u"),
    ("seed", "u"), ("dead_end", "enum"), ("smoothing", "enum"), ("tighten", "bool"),
    ("prune", "bool"), ("refine", "bool"),
]


def enc_params(p):
    out = bytearray()
    for name, kind in PARAM_FIELDS:
        v = p[name]
        if kind == "f":
            out += f32(v)
        elif kind == "bool":
            out.append(1 if v else 0)
        else:
            out += varint(v)
    return bytes(out)


def dec_params(r):
    p = {}
    for name, kind in PARAM_FIELDS:
        if kind == "f":
            p[name] = r.f32()
        elif kind == "bool":
            p[name] = r.byte() != 0
        else:
            p[name] = r.varint()
    return p


def req_hello():
    return varint(0)


def req_set_map(width, height, offset, total_len, chunk):
    return (varint(1) + varint(width) + varint(height) + varint(offset) + varint(total_len)
            + byte_str(chunk))


def req_set_params(p):
    return varint(2) + enc_params(p)


def req_plan(start, goal, seed=None):
    s = b"\x00" if seed is None else b"\x01" + varint(seed)
    return varint(3) + varint(start[0]) + varint(start[1]) + varint(goal[0]) + varint(goal[1]) + s


def req_cancel():
    return varint(4)


def req_stats():
    return varint(5)


STATS_FIELDS = ["uptime", "boots", "frames_ok", "frames_bad", "rx_overruns", "rx_bytes",
                "tx_frames", "plans", "plan_errors", "cancelled", "busy", "last_plan_ticks",
                "map_width", "map_height", "queued"]


def dec_path(r):
    out = {"kind": "Path", "raw_length": r.f32(), "length": r.f32(), "turns": r.varint(),
           "iterations": r.varint(), "best_iteration": r.varint(), "moves": r.varint(),
           "ticks": r.varint(), "raw_cells": r.varint(),
           "origin": ("cold", "warm", "reused", "repaired")[min(r.byte(), 3)]}
    w = r.bytes()
    out["waypoints"] = [struct.unpack_from("<HH", w, i) for i in range(0, len(w), 4)]
    out["directions"] = list(r.bytes())
    return out


def dec_reply(body):
    r = Reader(body)
    rid = r.varint()
    tag = r.varint()
    if tag == 0:
        out = {"kind": "Hello", "protocol_version": r.varint(), "firmware_version": r.str(),
               "board": r.str()}
        out["capacity"] = {k: r.varint() for k in
                           ["cells", "max_side", "max_steps", "max_chunk", "max_request",
                            "plan_queue", "tick_hz", "window", "window_bytes"]}
        out["defaults"] = dec_params(r)
    elif tag == 1:
        out = {"kind": "Ack"}
    elif tag == 2:
        out = dec_path(r)
    elif tag == 3:
        code = r.byte()
        out = {"kind": "Error", "code": code, "name": ERRORS.get(code, "?"),
               "detail": r.varint(), "limit": r.varint()}
    elif tag == 4:
        out = {"kind": "Stats"}
        for k in STATS_FIELDS:
            out[k] = r.varint()
        out["planning"] = r.byte() != 0
        out["stack_peak"] = r.varint()
        out["replies_dropped"] = r.varint()
        out["parted"] = r.varint()
    elif tag == 5:
        # One part of a long path: the parts' bytes together are a Path reply's body.
        out = {"kind": "PathPart", "offset": r.varint(), "total_len": r.varint(),
               "bytes": r.bytes()}
    else:
        raise ValueError(f"unknown reply {tag}")
    if not r.done():
        raise ValueError("trailing bytes")
    return rid, out


# ---- maps ------------------------------------------------------------------------------------


def load_map(path):
    lines = open(path).read().split("\n")
    i = lines.index("map") + 1
    rows = [l for l in lines[i:] if l]
    h, w = len(rows), len(rows[0])
    bits = bytearray((w * h + 7) // 8)
    for y, row in enumerate(rows):
        for x, c in enumerate(row):
            if c not in ".GS":
                k = y * w + x
                bits[k // 8] |= 1 << (k % 8)
    return w, h, bytes(bits), rows


DX = [1, 1, 0, -1, -1, -1, 0, 1]
DY = [0, 1, 1, 1, 0, -1, -1, -1]


def raw_cells(start, dirs):
    x, y = start
    out = [(x, y)]
    for d in dirs:
        x, y = x + DX[d], y + DY[d]
        out.append((x, y))
    return out


# ---- connection ------------------------------------------------------------------------------


class Device:
    def __init__(self, host, port, timeout=60.0):
        deadline = time.time() + 10
        while True:
            try:
                self.s = socket.create_connection((host, port), timeout=timeout)
                break
            except OSError:
                if time.time() > deadline:
                    raise
                time.sleep(0.1)
        self.s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.buf = bytearray()
        self.parts = {}
        self.next_id = 1
        self.s.sendall(b"\x00")  # resynchronise the device's frame reader

    def send_raw(self, wire):
        self.s.sendall(wire)

    def send(self, body, rid=None):
        if rid is None:
            rid = self.next_id
            self.next_id += 1
        self.send_raw(frame(varint(rid) + body))
        return rid

    def recv(self):
        """The next whole reply: the parts of a long path are put together into one Path
        (other replies that come between them are returned first)."""
        while True:
            rid, reply = self.recv_frame()
            if reply["kind"] != "PathPart":
                return rid, reply
            parts = self.parts.setdefault(rid, bytearray())
            if reply["offset"] != len(parts):
                raise ValueError(f"part of reply {rid} at {reply['offset']}, expected {len(parts)}")
            parts += reply["bytes"]
            if len(parts) >= reply["total_len"]:
                del self.parts[rid]
                r = Reader(bytes(parts))
                path = dec_path(r)
                if not r.done():
                    raise ValueError("trailing bytes in a path's parts")
                return rid, path

    def recv_frame(self):
        while True:
            if 0 in self.buf:
                i = self.buf.index(0)
                wire, self.buf = bytes(self.buf[:i]), self.buf[i + 1 :]
                if wire:
                    return dec_reply(unframe(wire))
                continue
            chunk = self.s.recv(65536)
            if not chunk:
                raise EOFError("device closed the connection")
            self.buf += chunk

    def call(self, body):
        rid = self.send(body)
        got, reply = self.recv()
        if got != rid:
            raise AssertionError(f"reply id {got}, expected {rid}: {reply}")
        return reply

    def set_map(self, w, h, bits, chunk=128):
        for off in range(0, len(bits), chunk):
            r = self.call(req_set_map(w, h, off, len(bits), bits[off : off + chunk]))
            if r["kind"] != "Ack":
                return r
        return {"kind": "Ack"}


def parse_point(s):
    x, y = s.split(",")
    return int(x), int(y)


def show_path(reply, rows, start):
    if reply["kind"] != "Path":
        print(reply)
        return
    raw = set(raw_cells(start, reply["directions"]))
    wp = set(reply["waypoints"])
    for y, row in enumerate(rows):
        line = []
        for x, c in enumerate(row):
            line.append("o" if (x, y) in wp else "*" if (x, y) in raw else "." if c in ".GS" else "#")
        print(" ".join(line))
    print(f"raw {reply['raw_length']:.3f}  smoothed {reply['length']:.3f}  {reply['turns']} turns  "
          f"{reply['iterations']} iterations (best at {reply['best_iteration']})  "
          f"{reply['ticks']} ticks  waypoints {reply['waypoints']}")


# ---- self test -------------------------------------------------------------------------------


def expect(reply, kind, code=None):
    if reply["kind"] != kind or (code is not None and reply.get("name") != code):
        raise AssertionError(f"expected {kind} {code or ''}, got {reply}")
    return reply


def selftest(dev, map_path):
    w, h, bits, rows = load_map(map_path)
    hello = expect(dev.call(req_hello()), "Hello")
    assert hello["protocol_version"] == PROTOCOL_VERSION, hello
    defaults = hello["defaults"]
    print("hello:", hello["board"], hello["firmware_version"], hello["capacity"])

    # Before any map: NoMap.
    st = expect(dev.call(req_stats()), "Stats")
    if st["map_width"] == 0:
        expect(dev.call(req_plan((0, 0), (1, 1))), "Error", "NoMap")

    # Map uploads: too large, out-of-sequence chunk, then the real one in small chunks.
    # Checks in order: chunk size, then the header (zero side, too large, total_len), then the
    # upload's continuity.
    cap = hello["capacity"]
    wide = cap["max_side"] + 1
    r = expect(dev.call(req_set_map(wide, 2, 0, (wide * 2 + 7) // 8, b"\x00" * 16)), "Error",
               "MapTooLarge")
    assert (r["detail"], r["limit"]) == (wide, cap["max_side"]), r
    long_side = cap["max_side"]
    rows_over = cap["cells"] // long_side + 1   # within the side, over the cells
    r = expect(dev.call(req_set_map(long_side, rows_over, 0, 1, b"\x00")), "Error", "MapTooLarge")
    assert (r["detail"], r["limit"]) == (long_side * rows_over, cap["cells"]), r
    r = expect(dev.call(req_set_map(0, 3, 0, 7, b"\x00")), "Error", "BadMap")
    assert (r["detail"], r["limit"]) == (7, 0), r
    r = expect(dev.call(req_set_map(w, h, 0, len(bits), b"")), "Error", "TooLarge")
    assert (r["detail"], r["limit"]) == (0, cap["max_chunk"]), r
    expect(dev.call(req_set_map(w, h, 5, len(bits), b"\x00")), "Error", "BadChunk")
    r = expect(dev.call(req_set_map(w, h, 0, 200, b"\x00" * 200)), "Error", "TooLarge")
    assert (r["detail"], r["limit"]) == (200, hello["capacity"]["max_chunk"]), r
    expect(dev.set_map(w, h, bits, chunk=17), "Ack")

    # A plan, raw path and waypoints checked against the map.
    start, goal = (0, 0), (w - 1, h - 1)
    p = expect(dev.call(req_plan(start, goal)), "Path")
    cells = raw_cells(start, p["directions"])
    assert cells[-1] == goal and len(cells) == p["raw_cells"], p
    assert all(rows[y][x] in ".GS" for x, y in cells), "raw path crosses an obstacle"
    assert p["waypoints"][0] == start and p["waypoints"][-1] == goal, p
    print(f"plan: length {p['length']:.3f} raw {p['raw_length']:.3f}, {p['iterations']} "
          f"iterations, {p['ticks']} ticks")

    # Same seed, same path; bad params refused.
    again = expect(dev.call(req_plan(start, goal, seed=defaults["seed"])), "Path")
    assert again["directions"] == p["directions"] and again["waypoints"] == p["waypoints"]
    bad = dict(defaults, rho=0.0)
    r = expect(dev.call(req_set_params(bad)), "Error", "BadParam")
    assert r["detail"] == 4, r
    expect(dev.call(req_plan((1, 1), goal)), "Error", "StartBlocked") if rows[1][1] not in ".GS" \
        else None
    expect(dev.call(req_plan((w, 0), goal)), "Error", "StartOutOfBounds")

    # Busy and Cancel: a long plan, the queue filled, one more refused, then cancel them all.
    slow = dict(defaults, iterations=2000, patience=0, refine_patience=0)
    expect(dev.call(req_set_params(slow)), "Ack")
    queue = hello["capacity"]["plan_queue"]
    ids = [dev.send(req_plan(start, goal, seed=s)) for s in range(1, queue + 3)]
    replies = {}
    rid, r = dev.recv()  # the refused one comes back at once
    replies[rid] = r
    assert r["kind"] == "Error" and r["name"] == "Busy" and rid == ids[-1], (rid, r)
    st = expect(dev.call(req_stats()), "Stats")
    assert st["planning"] and st["queued"] == queue, st
    cancel_id = dev.send(req_cancel())
    while len(replies) < len(ids) + 1:
        rid, r = dev.recv()
        replies[rid] = r
    expect(replies[cancel_id], "Ack")
    for i in ids[:-1]:
        expect(replies[i], "Error", "Cancelled")
    print(f"busy + cancel: {queue + 1} plans cancelled, 1 refused")

    # A new map during a plan cancels it.
    pid = dev.send(req_plan(start, goal))
    time.sleep(0.05)
    mid = dev.send(req_set_map(w, h, 0, len(bits), bits))
    got = dict([dev.recv(), dev.recv()])
    expect(got[pid], "Error", "Cancelled")
    expect(got[mid], "Ack")
    expect(dev.call(req_set_params(defaults)), "Ack")

    # Corrupted frames: bad CRC, garbage, oversize; each answered with id 0.
    body = varint(999) + req_hello()
    good = cobs_decode(frame(body)[:-1])
    bad = bytearray(good)
    bad[1] ^= 0x01
    dev.send_raw(cobs_encode(bytes(bad)) + b"\x00")
    rid, r = dev.recv()
    assert rid == 0 and r["name"] == "BadCrc", (rid, r)
    dev.send_raw(b"\x05\x01\x02\x00")
    rid, r = dev.recv()
    assert rid == 0 and r["name"] == "Undecodable", (rid, r)
    dev.send_raw(b"\x01" * 600 + b"\x00")
    rid, r = dev.recv()
    assert rid == 0 and r["name"] == "TooLarge" and r["detail"] == 600, (rid, r)
    expect(dev.call(req_hello()), "Hello")

    st = expect(dev.call(req_stats()), "Stats")
    assert st["frames_bad"] >= 3 and st["busy"] >= 1 and st["cancelled"] >= queue + 2, st
    assert 0 < st["stack_peak"] < 64 * 1024, st
    print("stats:", {k: v for k, v in st.items() if k != "kind"})
    print("selftest passed")


# ---- stack high-water mark -------------------------------------------------------------------


def synthetic_maps():
    """Maps for the worst cases: (name, rows, start, goal)."""
    open32 = ["." * 32] * 32
    # Corridors on the even rows, joined by one gap a wall row, alternately at the right and the
    # left end: a path through every free row, about 530 cells.
    snake = []
    for y in range(32):
        if y % 2 == 0 and y < 31:
            snake.append("." * 32)
        else:
            gap = 31 if (y // 2) % 2 == 0 else 0
            snake.append("".join("." if x == gap and y < 31 else "@" for x in range(32)))
    return [
        ("open-32x32", open32, (0, 0), (31, 31)),
        ("snake-32x32", snake, (0, 0), (0, 30)),
        # A long path within the device's 65,536 cells and 2,047-step ant paths: along row 0,
        # down at the right end, back along row 2, down at the left, along row 4 (772 cells).
        ("zigzag-256x5", ["." * 256, "@" * 255 + ".", "." * 256, "." + "@" * 255, "." * 256],
         (0, 0), (255, 4)),
    ]


def rows_to_bits(rows):
    h, w = len(rows), len(rows[0])
    bits = bytearray((w * h + 7) // 8)
    for y, row in enumerate(rows):
        for x, c in enumerate(row):
            if c not in ".GS":
                k = y * w + x
                bits[k // 8] |= 1 << (k % 8)
    return w, h, bytes(bits)


def stack_cases(defaults):
    """Parameter sets that exercise every code path of a plan: each algorithm, each smoothing,
    dead ends that kill ants, full runs without early stop."""
    d = dict(defaults)
    return [
        ("ohaca shortest", dict(d)),
        ("ohaca greedy", dict(d, smoothing=SMOOTHING.index("greedy"))),
        ("ohaca none", dict(d, smoothing=SMOOTHING.index("none"), tighten=False)),
        ("aca full run", dict(d, algorithm=ALGORITHMS.index("aca"), patience=0)),
        ("ohaca full run", dict(d, patience=0, refine_patience=0, iterations=30)),
        ("paca", dict(d, algorithm=ALGORITHMS.index("paca"))),
        ("haca", dict(d, algorithm=ALGORITHMS.index("haca"))),
        ("aca die", dict(d, algorithm=ALGORITHMS.index("aca"), dead_end=DEAD_ENDS.index("die"))),
    ]


def stack_probe(dev, map_path):
    """Run the requests that go deepest into the stack; return Stats.stack_peak."""
    hello = expect(dev.call(req_hello()), "Hello")
    defaults = hello["defaults"]
    w, h, bits, _ = load_map(map_path)
    maps = [(map_path, w, h, bits, (0, 0), (w - 1, h - 1))]
    for name, rows, start, goal in synthetic_maps():
        maps.append((name, *rows_to_bits(rows), start, goal))
    for name, w, h, bits, start, goal in maps:
        cap = hello["capacity"]
        if w * h > cap["cells"] or max(w, h) > cap["max_side"]:
            continue
        expect(dev.set_map(w, h, bits), "Ack")
        for label, params in stack_cases(defaults):
            expect(dev.call(req_set_params(params)), "Ack")
            r = dev.call(req_plan(start, goal))
            st = expect(dev.call(req_stats()), "Stats")
            what = (f"{r['raw_cells']} cells, {len(r['waypoints'])} waypoints, "
                    f"{r['iterations']} iterations" if r["kind"] == "Path" else r.get("name"))
            print(f"  {name:<22} {label:<16} {what:<45} stack peak {st['stack_peak']}")
    expect(dev.call(req_set_params(defaults)), "Ack")
    st = expect(dev.call(req_stats()), "Stats")
    return st["stack_peak"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--host", default="127.0.0.1")
    ap.add_argument("--port", type=int, default=4444)
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("hello")
    sub.add_parser("stats")
    sub.add_parser("cancel")
    pl = sub.add_parser("plan")
    pl.add_argument("--map", required=True)
    pl.add_argument("--start", type=parse_point, required=True)
    pl.add_argument("--goal", type=parse_point, required=True)
    pl.add_argument("--seed", type=int)
    pl.add_argument("--repeat", type=int, default=1, help="plan this many times (seeds seed..)")
    st = sub.add_parser("selftest")
    st.add_argument("--map", default="maps/complex-26.map")
    sp = sub.add_parser("stack", help="run the deepest-stack requests, print Stats.stack_peak")
    sp.add_argument("--map", default="maps/complex-26.map")
    args = ap.parse_args()

    dev = Device(args.host, args.port)
    if args.cmd == "hello":
        print(dev.call(req_hello()))
    elif args.cmd == "stats":
        print(dev.call(req_stats()))
    elif args.cmd == "cancel":
        print(dev.call(req_cancel()))
    elif args.cmd == "plan":
        w, h, bits, rows = load_map(args.map)
        r = dev.set_map(w, h, bits)
        if r["kind"] != "Ack":
            print(r)
            return 1
        for k in range(args.repeat):
            seed = None if args.seed is None and k == 0 else (args.seed or 1) + k
            reply = dev.call(req_plan(args.start, args.goal, seed))
            show_path(reply, rows, args.start)
            if reply["kind"] != "Path":
                return 1
    elif args.cmd == "selftest":
        selftest(dev, args.map)
    elif args.cmd == "stack":
        print(f"stack_peak {stack_probe(dev, args.map)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
