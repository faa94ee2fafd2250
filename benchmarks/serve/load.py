#!/usr/bin/env python3
"""Load on `twincal serve`: N assemblies through the TCP interface with the analytic
twin at d = 3, every locator, the active controller. Reports assemblies per second, the median
and p99 latency of propose and observe as the cell sees them (request written → reply read,
loopback TCP), and the database's size after a checkpoint.

    load.py TWINCAL [--assemblies 10000] [--durability full|normal] [--controller active]

The cell measures each assembly through `predict` (u_t − δu*_t on the twin); that request is
not counted in the latencies but is in the wall time.
"""
import argparse
import os
import statistics
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "examples", "python"))
from serve_client import ServeClient, weld  # noqa: E402


def percentile(values, p):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(p / 100 * len(ordered)))]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("twincal")
    parser.add_argument("--assemblies", type=int, default=10000)
    parser.add_argument("--durability", default="full")
    parser.add_argument("--controller", default="active")
    options = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        database = os.path.join(scratch, "load.db")
        client = ServeClient(options.twincal,
                             ["--db", database, "--case", "analytic", "--dimension", "3",
                              "--locators", "all", "--controller", options.controller,
                              "--durability", options.durability], tcp=True)
        proposes, observes = [], []
        start = time.perf_counter()
        for t in range(options.assemblies):
            assembly = (37 * t) % 100
            begin = time.perf_counter()
            proposal = client.call("propose", assembly=assembly)
            proposes.append(time.perf_counter() - begin)
            quality = weld(client, assembly, proposal["control"], t)
            begin = time.perf_counter()
            client.call("observe", request_id=proposal["request_id"], quality=quality)
            observes.append(time.perf_counter() - begin)
        elapsed = time.perf_counter() - start
        size = client.call("checkpoint")["bytes"]
        client.close()
    print(f"{options.assemblies} assemblies, {options.controller}, durability "
          f"{options.durability}: {options.assemblies / elapsed:.0f} assemblies/s "
          f"({elapsed:.1f} s)")
    for name, values in (("propose", proposes), ("observe", observes)):
        print(f"  {name}: median {1e3 * statistics.median(values):.3f} ms, "
              f"p99 {1e3 * percentile(values, 99):.3f} ms, max {1e3 * max(values):.3f} ms")
    print(f"  database: {size / 1e6:.2f} MB ({size / options.assemblies:.0f} bytes per assembly)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
