#!/usr/bin/env python3
"""A minimal external twin for twincal (docs/external.md, "Writing an external twin").

twincal starts this program and talks to it in JSON lines on stdin/stdout, one request, one
reply:
    request  {"id": 7, "assembly": {"upper": 3, "lower": 5}, "controls": [[u1, u2, u3], ...]}
             (an assembly of scanned parts, from `twincal serve`: {"parts": <what the cell sent>})
    reply    {"id": 7, "qualities": [q1, ...]}     one quality per control, in order
         or  {"id": 7, "error": "why"}             twincal reports it; nothing is retried
A real twin replaces `quality` with its simulation (an FEM job, RD&T, ...). Anything written to
stderr reaches twincal's stderr; nothing but replies may go to stdout.

This one is a geometric-quality stand-in: the RMS deviation of an assembly is
    Q(x, u) = sqrt(q0(x) + sum_i w_i (u_i - a_i(x))^2)
with a part-dependent best adjustment a(x) and spread q0(x) from the part indices, or from
scanned parts {"upper": [deviations...], "lower": [...]} through the sums of their deviations.
"""
import json
import math
import sys

WEIGHTS = [1.0, 0.6, 0.3]


def quality(assembly, control):
    if "parts" in assembly:
        upper, lower = sum(assembly["parts"]["upper"]), sum(assembly["parts"]["lower"])
    else:
        upper, lower = assembly["upper"], assembly["lower"]
    q0 = 0.04 + 0.01 * ((3 * upper + 5 * lower) % 7)
    best = [0.2 * math.sin(1.7 * upper + 0.9 * lower + i) for i in range(len(WEIGHTS))]
    return math.sqrt(q0 + sum(w * (u - a) ** 2 for w, u, a in zip(WEIGHTS, control, best)))


def main():
    for line in sys.stdin:
        request = json.loads(line)
        try:
            qualities = [quality(request["assembly"], u) for u in request["controls"]]
            reply = {"id": request["id"], "qualities": qualities}
        except (KeyError, TypeError, ValueError) as error:
            reply = {"id": request.get("id"), "error": f"cannot evaluate: {error!r}"}
        print(json.dumps(reply), flush=True)


if __name__ == "__main__":
    main()
