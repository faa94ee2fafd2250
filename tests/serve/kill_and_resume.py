#!/usr/bin/env python3
"""`twincal serve` survives kill -9 (issue 14): a cell of 100 assemblies whose server is killed
at 10 random moments and resumed from its database ends with the same controls, δû and P, bit
for bit, as a cell whose server ran uninterrupted.

    kill_and_resume.py TWINCAL CONTROLLER [SEED]

Each kill lands right after a request was written, sometimes after a short random wait, so it
meets the server reading, computing, writing the database or replying. After each kill the cell
restarts the server with --resume, asks `state` how far the history got, and goes on from
there: a proposal that was recorded but whose reply was lost is answered again.
"""
import json
import os
import random
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "examples", "python"))
from serve_client import ServeClient, weld  # noqa: E402

ASSEMBLIES = 100
KILLS = 10


class Killed(Exception):
    pass


class KillingClient:
    """A ServeClient that kill -9s its server when its request counter meets a kill point."""

    def __init__(self, twincal, arguments, kill_points, rng):
        self.twincal, self.arguments = twincal, arguments
        self.kill_points, self.rng = kill_points, rng
        self.requests = 0
        self.client = ServeClient(twincal, arguments)

    def call(self, op, **fields):
        self.requests += 1
        if self.requests in self.kill_points:
            self.client.send({"op": op, **fields})
            time.sleep(self.rng.choice([0.0, 0.0005, 0.002]))
            self.client.kill()
            self.client = ServeClient(self.twincal, ["--db", self.arguments[1], "--resume",
                                                     "--durability", "normal"])
            raise Killed()
        return self.client.call(op, **fields)


def run_cell(twincal, controller, database, kill_points, rng):
    arguments = ["--db", database, "--case", "analytic", "--dimension", "3", "--locators", "all",
                 "--controller", controller, "--durability", "normal"]
    cell = KillingClient(twincal, arguments, kill_points, rng)
    controls = [None] * ASSEMBLIES
    t = 0
    while t < ASSEMBLIES:
        try:
            assembly = (37 * t) % 100
            proposal = cell.call("propose", assembly=assembly)
            controls[t] = proposal["control"]
            quality = weld(cell, assembly, proposal["control"], t)
            cell.call("observe", request_id=proposal["request_id"], quality=quality)
            t += 1
        except Killed:
            t = cell.client.call("state")["observed"]  # how far the history got
    state = cell.call("state")
    cell.client.close()
    return controls, state


def main():
    twincal, controller = sys.argv[1], sys.argv[2]
    seed = int(sys.argv[3]) if len(sys.argv) > 3 else 2023
    rng = random.Random(seed)
    # About 3 requests per assembly (propose, predict, observe) after the first.
    kill_points = set(rng.sample(range(2, 3 * ASSEMBLIES), KILLS))
    with tempfile.TemporaryDirectory() as scratch:
        expected, expected_state = run_cell(twincal, controller, os.path.join(scratch, "a.db"),
                                            set(), rng)
        controls, state = run_cell(twincal, controller, os.path.join(scratch, "b.db"),
                                   kill_points, rng)
    failures = []
    for t, (got, want) in enumerate(zip(controls, expected)):
        if got != want:
            failures.append(f"assembly {t}: control {got} != {want}")
    for key in ("observed", "estimate", "covariance"):
        if state[key] != expected_state[key]:
            failures.append(f"{key}: {json.dumps(state[key])} != {json.dumps(expected_state[key])}")
    print(f"{controller}: {ASSEMBLIES} assemblies, {KILLS} kill -9 at requests "
          f"{sorted(kill_points)} (seed {seed}); final estimate {state['estimate']}")
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures[:10]), file=sys.stderr)
        return 1
    print("identical to the uninterrupted run: every control, δû and P")
    return 0


if __name__ == "__main__":
    sys.exit(main())
