#!/usr/bin/env python3
"""Soak of `twincal serve` over TCP, and the cost of resuming what it wrote (docs/serve.md,
"Soak and resume"). Standard library only; a benchmark, not a test (it takes minutes).

    python3 soak.py /path/to/twincal [--assemblies 1000000] [--churn 20] [--db FILE]
                    [--no-verify-all]

One cell client drives the analytic twin (d = 3, every locator, the active controller,
`--durability normal`, snapshots every 1000 observations) through propose → predict (the cell's
measurement: the twin at u_t minus a hidden drifting offset) → observe, for N assemblies, while
`--churn` other clients connect, ask `state`, and drop at random (some mid-line). It prints the
assemblies per second, the propose and observe latencies (median, p99, max), the server's
resident memory (VmRSS) at 10^4, 10^5 and N assemblies, and the database size per assembly.
Then it kills the server (SIGKILL) and times `--resume` (from the last snapshot) and
`--resume --verify-all` (the whole history replayed), each with its peak memory.
"""
import argparse
import json
import math
import os
import random
import resource
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time


def rss_kb(pid):
    with open(f"/proc/{pid}/status", encoding="ascii") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return -1


def percentile(values, p):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(p * len(ordered)))]


class Connection:
    def __init__(self, port):
        self.socket = socket.create_connection(("127.0.0.1", port))
        self.reader = self.socket.makefile("r", encoding="utf-8", newline="\n")

    def call(self, request):
        self.socket.sendall((json.dumps(request) + "\n").encode())
        reply = json.loads(self.reader.readline())
        if not reply["ok"]:
            raise RuntimeError(reply)
        return reply

    def close(self):
        self.reader.close()
        self.socket.close()


def churn(port, stop, seed, counts):
    """Connects, asks for the state or sends half a line, drops; again, until `stop`."""
    rng = random.Random(seed)
    while not stop.is_set():
        try:
            connection = Connection(port)
            for _ in range(rng.randint(0, 3)):
                connection.call({"op": "state"})
            if rng.random() < 0.3:
                connection.socket.sendall(b'{"op": "sta')  # dropped mid-line
            connection.close()
            counts[0] += 1
        except OSError:
            counts[1] += 1
        time.sleep(rng.uniform(0.0, 0.05))


def timed_resume(twincal, database, extra):
    """Seconds until a resumed server listens, and its peak RSS (kB) by then."""
    start = time.perf_counter()
    server = subprocess.Popen([twincal, "serve", "--db", database, "--resume", *extra,
                               "--durability", "normal", "--listen", "127.0.0.1:0"],
                              stderr=subprocess.PIPE, text=True)
    lines = []
    while True:
        line = server.stderr.readline()
        if not line:
            raise RuntimeError("resume failed: " + "".join(lines))
        lines.append(line)
        if "listening on" in line:
            break
    seconds = time.perf_counter() - start
    with open(f"/proc/{server.pid}/status", encoding="ascii") as status:
        peak = next(int(l.split()[1]) for l in status if l.startswith("VmHWM:"))
    port = int(line.rsplit(":", 1)[1])
    connection = Connection(port)
    state = connection.call({"op": "state"})
    connection.call({"op": "shutdown"})
    connection.close()
    server.wait(timeout=60)
    return seconds, peak, state["observed"]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("twincal")
    parser.add_argument("--assemblies", type=int, default=1_000_000)
    parser.add_argument("--churn", type=int, default=20)
    parser.add_argument("--db")
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--no-verify-all", action="store_true",
                        help="skip timing --resume --verify-all (it replays everything)")
    args = parser.parse_args()
    scratch = tempfile.mkdtemp(prefix="twincal-soak-")
    database = args.db or os.path.join(scratch, "soak.db")
    server = subprocess.Popen([args.twincal, "serve", "--db", database, "--case", "analytic",
                               "--dimension", "3", "--locators", "all", "--controller", "active",
                               "--durability", "normal", "--snapshot-every", "1000",
                               "--listen", "127.0.0.1:0"], stderr=subprocess.PIPE, text=True)
    line = server.stderr.readline()
    port = int(line.rsplit(":", 1)[1])
    stop = threading.Event()
    counts = [0, 0]
    churners = [threading.Thread(target=churn, args=(port, stop, args.seed + k, counts), daemon=True)
                for k in range(args.churn)]
    for thread in churners:
        thread.start()
    cell = Connection(port)
    propose_ms, observe_ms, memory = [], [], {}
    start = time.perf_counter()
    for t in range(args.assemblies):
        offset = [0.3 * math.sin(0.001 * t + i) for i in range(3)]  # hidden, drifting δu*
        t0 = time.perf_counter()
        proposal = cell.call({"op": "propose", "assembly": (7 * t) % 100})
        t1 = time.perf_counter()
        control = [u - o for u, o in zip(proposal["control"], offset)]
        quality = cell.call({"op": "predict", "assembly": (7 * t) % 100,
                             "control": control})["quality"]
        t2 = time.perf_counter()
        cell.call({"op": "observe", "request_id": proposal["request_id"], "quality": quality})
        t3 = time.perf_counter()
        propose_ms.append(1e3 * (t1 - t0))
        observe_ms.append(1e3 * (t3 - t2))
        if t + 1 in (10_000, 100_000, args.assemblies):
            memory[t + 1] = rss_kb(server.pid)
    seconds = time.perf_counter() - start
    stop.set()
    for thread in churners:
        thread.join(timeout=5)
    cell.call({"op": "checkpoint"})
    size = os.path.getsize(database)
    os.kill(server.pid, signal.SIGKILL)
    server.wait()
    print(f"{args.assemblies} assemblies in {seconds:.0f} s: {args.assemblies / seconds:.0f} "
          f"assemblies/s (3 requests each) with {args.churn} churning clients "
          f"({counts[0]} connections, {counts[1]} refused)")
    for name, values in (("propose", propose_ms), ("observe", observe_ms)):
        print(f"  {name}: median {percentile(values, 0.5):.3f} ms, p99 "
              f"{percentile(values, 0.99):.3f} ms, max {max(values):.1f} ms")
    print("  server VmRSS: " + ", ".join(f"{kb / 1024:.1f} MB at {n}" for n, kb in memory.items()))
    print(f"  database: {size / 2**20:.0f} MB, {size / args.assemblies:.0f} bytes per assembly")
    resumes = [("--resume", [])]
    if not args.no_verify_all:
        resumes.append(("--resume --verify-all", ["--verify-all"]))
    for label, extra in resumes:
        seconds, peak, observed = timed_resume(args.twincal, database, extra)
        print(f"  {label}: listening after {seconds:.2f} s, peak VmHWM {peak / 1024:.1f} MB, "
              f"{observed} observations")
    return 0


if __name__ == "__main__":
    sys.exit(main())
