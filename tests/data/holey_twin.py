#!/usr/bin/env python3
"""A twin with a hole, for the u0 search's tests: the minimal twin's quality
sqrt(q0 + sum_i w_i (u_i - a_i)^2) (examples/external_twin/minimal_twin.py), except that it answers
null where u_1 > 0.5, as a solver answers where it does not converge. Every optimum (a_1 within
+-0.2) lies outside the hole."""
import json
import math
import sys

WEIGHTS = [1.0, 0.6, 0.3]


def quality(assembly, control):
    if control[0] > 0.5:
        return None
    upper, lower = assembly["upper"], assembly["lower"]
    q0 = 0.04 + 0.01 * ((3 * upper + 5 * lower) % 7)
    best = [0.2 * math.sin(1.7 * upper + 0.9 * lower + i) for i in range(len(WEIGHTS))]
    return math.sqrt(q0 + sum(w * (u - a) ** 2 for w, u, a in zip(WEIGHTS, control, best)))


for line in sys.stdin:
    request = json.loads(line)
    qualities = [quality(request["assembly"], u) for u in request["controls"]]
    print(json.dumps({"id": request["id"], "qualities": qualities}), flush=True)
