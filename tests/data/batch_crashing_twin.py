#!/usr/bin/env python3
"""The minimal twin (examples/external_twin/minimal_twin.py) that crashes (exit status 3) on every
request of more than one control, as a solver that runs out of memory on a batch: the u0 search
(one control per request) works, a w-controller's episode (candidates x sigma points per request)
fails every time, restarted or not."""
import json
import math
import os
import sys

WEIGHTS = [1.0, 0.6, 0.3]


def quality(assembly, control):
    upper, lower = assembly["upper"], assembly["lower"]
    q0 = 0.04 + 0.01 * ((3 * upper + 5 * lower) % 7)
    best = [0.2 * math.sin(1.7 * upper + 0.9 * lower + i) for i in range(len(WEIGHTS))]
    return math.sqrt(q0 + sum(w * (u - a) ** 2 for w, u, a in zip(WEIGHTS, control, best)))


for line in sys.stdin:
    request = json.loads(line)
    if len(request["controls"]) > 1:
        os._exit(3)
    qualities = [quality(request["assembly"], u) for u in request["controls"]]
    print(json.dumps({"id": request["id"], "qualities": qualities}), flush=True)
